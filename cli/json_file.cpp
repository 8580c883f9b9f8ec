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

}  // namespace sailshape::cli
