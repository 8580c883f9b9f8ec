// `sailshape crop`: a scan cut down to the region a sail flies in, for scripts.
#include <cstdio>
#include <memory>

#include "analysis/core/errors.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "cli/commands.hpp"
#include "cli/sail_design.hpp"

namespace sailshape::cli {
namespace {

struct CropOptions {
  std::string input, box, design, out;
  double margin = 0;
  bool margin_given = false;  // otherwise: the design's plausible trim deviation
};

void run(const CropOptions& o) {
  if (o.box.empty() == o.design.empty()) throw InvalidInput("crop: give either --box or --design");
  if (!o.box.empty() && o.margin_given) throw InvalidInput("crop: --margin applies to --design only");
  RegionBox region;
  if (!o.box.empty()) {
    region = parseRegionBox(o.box);
  } else {
    const DesignFile f = readDesignFile(o.design);
    region = designRegion(f.design.mesh, o.margin_given ? o.margin : plausibleTrimDeviationM(f.design.mesh));
  }
  CloudReadResult read = readCloud(o.input);
  for (const auto& w : read.warnings) std::fprintf(stderr, "warning: %s: %s\n", o.input.c_str(), w.c_str());
  // Mixed pixels are told by the surfaces on both sides of them, which the crop cuts off.
  const Cloud cropped = cropToRegion(withoutMixedPixels(read.cloud, AnalysisParams{}), region);
  writeCloud(o.out, cropped);
  std::printf("wrote %zu of %zu points, inside %s m, to %s\n", cropped.size(), read.cloud.size(),
              formatRegionBox(region).c_str(), o.out.c_str());
}

}  // namespace

void addCropCommand(CLI::App& app) {
  auto o = std::make_shared<CropOptions>();
  CLI::App* cmd = app.add_subcommand(
      "crop",
      "Cut a scan down to the box a sail flies in: given, or its design's box with a margin\n\n"
      "Cut a scan (the whole tunnel or deck, in the boat frame) down to the points inside a box: given as "
      "XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX in metres, or a design's bounding box grown by a margin (by default as far as "
      "a plausible trim moves a sail from its design: a fifth of its mean chord). A scan that carries its samples' "
      "scan angles and viewpoint (sailshape's own) loses its mixed pixels first, on the whole scan, since the "
      "surfaces the crop cuts off tell them. The points keep their intensity, scan angles and the viewpoint.");
  cmd->add_option("SCAN", o->input, "Cloud file: .ply, .pcd, .xyz/.txt or .csv, metres, boat frame")->required();
  cmd->add_option("--box", o->box, "The box XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX, metres, boat frame");
  cmd->add_option("--design", o->design, "A design file (.dxf, .obj, .stl, .ply, as `design show` reads): its box");
  auto* margin = cmd->add_option("--margin", o->margin,
                  "With --design: metres added to every side of its box (default: a fifth of the design's mean chord)");
  cmd->add_option("--out", o->out, "Output cloud: .ply, .pcd, .xyz or .csv by its extension")->required();
  cmd->callback([o, margin] {
    o->margin_given = margin->count() > 0;
    run(*o);
  });
}

}  // namespace sailshape::cli
