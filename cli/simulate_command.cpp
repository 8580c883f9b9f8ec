// `sailshape simulate`: a synthetic scan of a generated sail, with its known answers.
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/sections/sections.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"

namespace sailshape::cli {
namespace {

struct SimulateOptions {
  std::string type = "main";
  size_t points = 40000;
  double noise_mm = 4.0;
  uint64_t seed = 1;
  bool scene = false;
  int sections = 3;
  std::string out, truth;
};

void run(const SimulateOptions& o) {
  const SailDesign design = exampleDesign(parseSailType(o.type));
  ScanSimulation sim;
  sim.points = o.points;
  sim.noise_sigma_m = o.noise_mm / 1000.0;
  sim.seed = o.seed;
  const Cloud cloud = o.scene ? sampleSailScene(design, sim).cloud : sampleSail(design, sim);
  writeCloud(o.out, cloud);
  std::fprintf(stderr, "wrote %s: %zu points (%s%s, noise %.1f mm)\n", o.out.c_str(), cloud.size(), o.type.c_str(),
               o.scene ? " in a scene with mast, boom and deck" : "", o.noise_mm);
  if (o.truth.empty()) return;
  SectionParams sp;
  sp.count = o.sections;
  const SailSurface surface(design);
  nlohmann::json doc;
  doc["type"] = sailTypeName(design.type);
  auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  doc["tack"] = vec(surface.tack());
  doc["clew"] = vec(surface.clew());
  doc["head"] = vec(surface.head());
  if (design.type == SailType::SquareTopMain) doc["peak"] = vec(surface.peak());
  for (double f : sectionFractions(sp)) {
    const KnownSection k = surface.section(f);
    doc["sections"].push_back({{"fraction", f},
                               {"chord_m", k.chord_m},
                               {"camber_pct", k.camber_pct},
                               {"draft_pct", k.draft_pct},
                               {"twist_deg", k.twist_deg},
                               {"entry_deg", k.entry_deg},
                               {"exit_deg", k.exit_deg}});
  }
  writeJsonFile(o.truth, doc);
}

}  // namespace

void addSimulateCommand(CLI::App& app) {
  auto opt = std::make_shared<SimulateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Write a synthetic scan of a generated sail with known section parameters\n\n"
      "Write a synthetic scan of a generated sail with known section parameters (for trying the pipeline "
      "and checking it against the truth).");
  cmd->add_option("--type", opt->type, "Sail type: main, square-top, jib or gennaker")
      ->check(CLI::IsMember({"main", "square-top", "jib", "gennaker"}))
      ->capture_default_str();
  cmd->add_option("--points", opt->points, "Points on the sail")->check(CLI::Range(100, 20'000'000))->capture_default_str();
  cmd->add_option("--noise-mm", opt->noise_mm, "Range noise σ in mm along the scanner's rays (SPEC: 4 mm)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Random seed")->capture_default_str();
  cmd->add_flag("--scene", opt->scene, "Add a mast, boom and deck around the sail");
  cmd->add_option("--sections", opt->sections, "Sections in the truth file")->check(CLI::Range(1, 100))->capture_default_str();
  cmd->add_option("--out", opt->out, "Output cloud (.ply, .pcd, .xyz, .csv)")->required();
  cmd->add_option("--truth", opt->truth, "Write the known corners and section parameters as JSON");
  cmd->callback([opt] { run(*opt); });
}

}  // namespace sailshape::cli
