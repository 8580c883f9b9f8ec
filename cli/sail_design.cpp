#include "cli/sail_design.hpp"

#include <cstdio>

#include "analysis/core/errors.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "cli/commands.hpp"

namespace sailshape::cli {

MeshSections designSections(const Mesh& design, const SectionParams& sections) {
  SectionParams sp = sections;
  sp.sensor_sigma_m = 0;  // a design has no measurement noise
  return analyzeMeshSections(design, {}, sp);
}

DesignFile readDesignFile(const std::string& path, const std::string& unit, const std::string& axes,
                          const SectionParams& sections) {
  DesignImportOptions io;
  io.unit = unit;
  io.axes = axes;
  DesignFile out;
  out.design = importDesign(path, io);
  try {
    out.sections = designSections(out.design.mesh, sections);
  } catch (const std::exception& e) {
    throw InvalidInput(path + ": not a sail's design surface (" + userMessage(e.what()) + ")");
  }
  return out;
}

void addDesignFileOptions(CLI::App* cmd, std::string& unit, std::string& axes) {
  cmd->add_option("--unit", unit, "File unit: auto (mm when the largest extent exceeds 100), m, mm or cm")
      ->check(CLI::IsMember({"auto", "m", "mm", "cm"}))
      ->capture_default_str();
  cmd->add_option("--axes", axes,
                  "File frame: auto (sailcut for DXF and Y-up meshes, else boat), boat (+X forward, +Y port, +Z up) "
                  "or sailcut (X tack to clew, Y up, Z depth)")
      ->check(CLI::IsMember({"auto", "boat", "sailcut"}))
      ->capture_default_str();
}

DesignCheck checkAgainstDesign(const Mesh& design, const MeshSections& design_sections, const SailAnalysis& flying) {
  DesignCheck out;
  out.comparison = compareWithDesign(design, design_sections.sections, flying.sail_cloud.points, flying.sections);
  out.mismatch = designMismatch(design, design_sections, flying, out.comparison.stats);
  if (!out.mismatch.empty()) std::fprintf(stderr, "warning: %s\n", out.mismatch.c_str());
  return out;
}

}  // namespace sailshape::cli
