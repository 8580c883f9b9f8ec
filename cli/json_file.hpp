#pragma once
// Writing the CLI's JSON documents.
#include <nlohmann/json.hpp>
#include <string>

namespace sailshape::cli {

// Writes `doc` indented to `path`; FileError names the file when it cannot be
// opened or written.
void writeJsonFile(const std::string& path, const nlohmann::json& doc);

}  // namespace sailshape::cli
