#pragma once
// A sail's design for the commands that analyse a scan of it (analyze --design,
// crop --design, db design add, db import for a sail with a design): read, checked to
// be a sail, and compared with what the analysis found.
#include <string>

#include <CLI/CLI.hpp>

#include "analysis/design/design_compare.hpp"
#include "analysis/io/design_import.hpp"
#include "analysis/pipeline/pipeline.hpp"

namespace sailshape::cli {

// The design's outline and sections, measured as the analysis measures a flying sail
// (`sections` as params.sections, without measurement noise).
MeshSections designSections(const Mesh& design, const SectionParams& sections);

struct DesignFile {
  DesignImport design;
  MeshSections sections;
};
// Reads a design file (analysis/io/design_import.hpp) and finds its outline. Throws
// InvalidInput naming the file when it is not a sail's surface.
DesignFile readDesignFile(const std::string& path, const std::string& unit = "auto", const std::string& axes = "auto",
                          const SectionParams& sections = {});

// `design show`'s table (or JSON to json_out) of a design: what the importer
// applied, corners, edge lengths, area and sections; `input` names it.
void printDesignReport(const std::string& input, const DesignImport& design, const MeshSections& sections,
                       const std::string& json_out = "");

// The flying sail against its design; a flying sail beyond a plausible trim of it
// (analysis/pipeline/sail_region.hpp designMismatch) is one warning line on stderr.
// `check` holds that line, empty when it flies as the design could.
struct DesignCheck {
  DesignComparison comparison;
  std::string mismatch;
};
DesignCheck checkAgainstDesign(const Mesh& design, const MeshSections& design_sections, const SailAnalysis& flying);

}  // namespace sailshape::cli
