#include "analysis/pipeline/params_io.hpp"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <functional>
#include <sstream>

#include "analysis/core/errors.hpp"

namespace sailshape {

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MixedPixelParams, jump_sigmas, max_incidence_deg, max_run_rad, max_missing)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(NormalParams, k_neighbours, orientation, robust)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RegionGrowingParams, k_neighbours, max_normal_angle_deg, max_curvature,
                                                min_points, max_points)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SailPickParams, method, seed_point, cluster_index, min_depth_m,
                                                min_depth_ratio, min_extent_m, max_tilt_deg, min_width_ratio)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SparSearchParams, min_radius_m, max_radius_m, min_length_radii,
                                                min_arc_deg, min_support, hypotheses, max_spars, seed)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(StatisticalOutlierParams, k_neighbours, std_ratio)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RadiusOutlierParams, radius_m, min_neighbours)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ReadmitParams, k_neighbours, max_offset_m, max_gap_factor, passes)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SmoothingParams, k_neighbours, reference_density_per_m2,
                                                max_radius_ratio,
                                                adapt_to_noise, polynomial_order, anchor_ratio, good_m, fair_m)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SurfaceParams, projection, max_edge_m, max_edge_factor,
                                                largest_component_only)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(OutlineParams, corners, corner_window_m, min_fourth_corner_deg,
                                                design_lengths_m, design_tolerance, design_warning,
                                                beam_exit_diameter_m, beam_divergence_rad, edges_against_sky)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SectionParams, count, fractions, plane, end_window, peak_window,
                                                normal_tolerance_deg, max_tilt_deg, max_iterations, normal_radius,
                                                noise_correlation_m, curve_points, max_bridged_gap)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(AnalysisParams, sensor_sigma_m, mixed_pixels, mixed, normals, segment,
                                                segmentation_voxel_sigmas, working_voxel_sigmas, working_column_depth_sigmas,
                                                working_voxel_of_extent, region_growing,
                                                sail_pick, find_spars, spars, statistical_outliers, statistical, radius_outliers, radius,
                                                readmit_surface_points, readmit, smooth, smoothing, surface, outline, sections)

namespace {

// Whether `value` can stand for a parameter whose default is `reference`: the same
// JSON kind, and for counts a whole number in range (nlohmann would silently truncate
// 20.5 to 20 and wrap −1 to 2^64 − 1). An empty default array says nothing about its
// elements: `probe` tries the value in the defaults document instead.
bool fits(const nlohmann::json& value, const nlohmann::json& reference, const std::function<bool()>& probe) {
  using Kind = nlohmann::json::value_t;
  switch (reference.type()) {
    case Kind::number_float:
      return value.is_number();
    case Kind::number_integer:
      return value.is_number_integer();
    case Kind::number_unsigned:
      return value.is_number_unsigned() || (value.is_number_integer() && value.get<long long>() >= 0);
    case Kind::array:
      if (!value.is_array()) return false;
      if (reference.empty()) return probe();
      for (const auto& v : value)
        if (!fits(v, reference.front(), probe)) return false;
      return true;
    default:
      return value.type() == reference.type();
  }
}

// "number", "integer", ... for the message "must be a number".
std::string kindName(const nlohmann::json& reference) {
  switch (reference.type()) {
    case nlohmann::json::value_t::number_float: return "number";
    case nlohmann::json::value_t::number_integer: return "integer";
    case nlohmann::json::value_t::number_unsigned: return "non-negative integer";
    case nlohmann::json::value_t::boolean: return "boolean";
    case nlohmann::json::value_t::array:
      return reference.empty() ? "array of the right values" : "array of " + kindName(reference.front()) + "s";
    default: return reference.type_name();
  }
}

std::string withArticle(const std::string& noun) {
  return (noun.find_first_of("aeiou") == 0 ? "an " : "a ") + noun;
}

// Every key of `doc` must exist in `reference` (the defaults), recursively, with a value
// of the default's kind. `root` is the whole defaults document, `pointer` where doc sits in it.
void checkKeys(const nlohmann::json& doc, const nlohmann::json& reference, const std::string& prefix,
               const nlohmann::json::json_pointer& pointer, const nlohmann::json& root) {
  if (!doc.is_object()) return;
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (!reference.contains(it.key())) throw InvalidInput("[paramsFromJson] unknown parameter '" + key + "'");
    const nlohmann::json& ref = reference[it.key()];
    if (ref.is_object()) {
      if (!it.value().is_object()) throw InvalidInput("[paramsFromJson] parameter '" + key + "' must be an object");
      checkKeys(it.value(), ref, key, pointer / it.key(), root);
      continue;
    }
    auto probe = [&] {
      nlohmann::json trial = root;
      trial[pointer / it.key()] = it.value();
      try {
        (void)trial.get<AnalysisParams>();
        return true;
      } catch (const nlohmann::json::exception&) {
        return false;
      }
    };
    if (!fits(it.value(), ref, probe))
      throw InvalidInput("[paramsFromJson] parameter '" + key + "' must be " + withArticle(kindName(ref)) + " (got " +
                         it.value().dump() + ")");
  }
}

nlohmann::json yamlToJson(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      nlohmann::json j = nlohmann::json::object();
      for (const auto& kv : node) j[kv.first.as<std::string>()] = yamlToJson(kv.second);
      return j;
    }
    case YAML::NodeType::Sequence: {
      nlohmann::json j = nlohmann::json::array();
      for (const auto& v : node) j.push_back(yamlToJson(v));
      return j;
    }
    case YAML::NodeType::Scalar: {
      const std::string s = node.Scalar();
      if (node.Tag() == "!") return s;  // quoted
      if (s == "true" || s == "True") return true;
      if (s == "false" || s == "False") return false;
      try {
        size_t used = 0;
        const long long i = std::stoll(s, &used);
        if (used == s.size()) return i;
      } catch (...) {
      }
      try {
        size_t used = 0;
        const double d = std::stod(s, &used);
        if (used == s.size()) return d;
      } catch (...) {
      }
      return s;
    }
    default:
      return nullptr;
  }
}

}  // namespace

nlohmann::json paramsToJson(const AnalysisParams& params) { return params; }

AnalysisParams paramsFromJson(const nlohmann::json& doc) {
  if (!doc.is_object()) throw InvalidInput("[paramsFromJson] the parameter document must be an object");
  const nlohmann::json defaults = paramsToJson(AnalysisParams{});
  checkKeys(doc, defaults, "", nlohmann::json::json_pointer(), defaults);
  try {
    return doc.get<AnalysisParams>();
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInput(std::string("[paramsFromJson] ") + e.what());
  }
}

AnalysisParams loadParams(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FileError(path + ": cannot open parameter file");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const bool yaml = path.size() >= 5 && (path.substr(path.size() - 5) == ".yaml" || path.substr(path.size() - 4) == ".yml");
  nlohmann::json doc;
  try {
    doc = yaml ? yamlToJson(YAML::Load(text)) : nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw FileError(path + ": " + (yaml ? "YAML" : "JSON") + " parse error: " + e.what());
  }
  try {
    return paramsFromJson(doc);
  } catch (const InvalidInput& e) {
    std::string msg = e.what();
    const std::string tag = "[paramsFromJson] ";
    if (msg.rfind(tag, 0) == 0) msg = msg.substr(tag.size());
    throw FileError(path + ": " + msg);
  }
}

}  // namespace sailshape
