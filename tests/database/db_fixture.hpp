#pragma once
// Temp-directory databases and analysis documents with known values.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

namespace sailshape::test {

class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "sailshape-db-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// An analysis document shaped like `sailshape analyze --json`: sections at
// 0.25, 0.5, 0.75 whose camber is base_camber + 1 %·k and draft 40 + k.
inline nlohmann::json analysisDoc(double base_camber_pct, int sections = 3) {
  nlohmann::json doc;
  doc["sail"] = {{"area_m2", 20.0}, {"corner_count", 3}};
  doc["luff"] = {{"lufa_sag_m", 0.1}};
  doc["diagnostics"] = {{"points_in", 50000}, {"stages", nlohmann::json::array({{{"name", "normals"}, {"seconds", 0.5}}})}};
  doc["parameters"] = {{"sensor_sigma_m", 0.004}};
  doc["sections"] = nlohmann::json::array();
  for (int k = 0; k < sections; ++k) {
    const double f = double(k + 1) / (sections + 1);
    nlohmann::json s = {{"fraction", f},          {"chord_m", 4.0 - k},      {"camber_pct", base_camber_pct + k},
                        {"draft_pct", 40.0 + k},  {"twist_deg", 10.0 + 5 * k}, {"twist_rel_deg", 5.0 * k},
                        {"entry_deg", 30.0},      {"exit_deg", nullptr},     {"plane_tilt_deg", 1.0},
                        {"converged", true}};
    s["uncertainty"] = {{"chord_m", 0.01}, {"camber_pct", 0.2},   {"draft_pct", 1.0},  {"twist_deg", 0.5},
                        {"twist_rel_deg", 0.5}, {"entry_deg", 1.0}, {"exit_deg", nullptr}};
    s["curve"] = {{0.0, 0.0, f}, {1.0, 0.1, f}, {2.0, 0.0, f}};
    doc["sections"].push_back(s);
  }
  return doc;
}

}  // namespace sailshape::test
