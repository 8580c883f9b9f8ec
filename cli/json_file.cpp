#include "cli/json_file.hpp"

#include <fstream>

#include "analysis/core/errors.hpp"

namespace sailshape::cli {

void writeJsonFile(const std::string& path, const nlohmann::json& doc) {
  std::ofstream out(path);
  if (!out) throw FileError(path + ": cannot open for writing");
  out << doc.dump(2) << "\n";
  out.close();
  if (!out) throw FileError(path + ": write failed");
}

nlohmann::json matrixJson(const Eigen::Matrix4d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

}  // namespace sailshape::cli
