#pragma once
// Writing the CLI's JSON documents.
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

namespace sailshape::cli {

// Writes `doc` indented to `path`; FileError names the file when it cannot be
// opened or written.
void writeJsonFile(const std::string& path, const nlohmann::json& doc);

// A 4×4 transform as four rows of four numbers.
nlohmann::json matrixJson(const Eigen::Matrix4d& m);

}  // namespace sailshape::cli
