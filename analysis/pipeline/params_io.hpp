#pragma once
// Pipeline parameters as JSON (and YAML) documents: every field of
// AnalysisParams by its name, nested by stage.
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "analysis/pipeline/pipeline.hpp"

namespace sailshape {

nlohmann::json paramsToJson(const AnalysisParams& params);

// One line per parameter, in paramsToJson's order: its dotted key
// ("region_growing.k_neighbours"), value (as JSON), unit and what it does.
std::string describeParams(const AnalysisParams& params);

// Starts from the defaults and overrides what the document sets. Throws
// InvalidInput naming an unknown key ("region_growing.k_neighbors") or a value
// of the wrong type.
AnalysisParams paramsFromJson(const nlohmann::json& doc);

// Reads a .json, .yaml or .yml file; FileError names the file and the parse error.
AnalysisParams loadParams(const std::string& path);

}  // namespace sailshape
