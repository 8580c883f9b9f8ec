#include "analysis/pipeline/params_io.hpp"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <functional>
#include <map>
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
                                                beam_exit_diameter_m, beam_divergence_rad, edges_against_sky,
                                                grazing_incidence_deg, scanner_max_range_m,
                                                scanner_position_sigma_m)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SectionParams, count, fractions, plane, end_window, peak_window,
                                                normal_tolerance_deg, max_tilt_deg, max_iterations, normal_radius,
                                                noise_correlation_m, curve_points, max_bridged_gap)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(AnalysisParams, sensor_sigma_m, mixed_pixels, mixed, estimate_viewpoint, normals, segment,
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


// Unit and meaning of every parameter, by its dotted key. Units: m, deg, rad;
// "σ" multiples of sensor_sigma_m; "points" counts; "× chord" fractions of a
// section's chord; "-" a switch, a name or a plain number.
struct ParamNote {
  const char* unit;
  const char* description;
};

const std::map<std::string, ParamNote>& paramNotes() {
  static const std::map<std::string, ParamNote> notes = {
      {"sensor_sigma_m", {"m", "range noise of the scanner (1σ, SPEC §3); sets smoothing and uncertainties"}},
      {"mixed_pixels", {"-", "drop mixed pixels (beams straddling an edge) when the scan has its scan angles"}},
      {"estimate_viewpoint", {"-", "a cloud without the scanner's position has it estimated from its samples' density"}},
      {"mixed.jump_sigmas", {"σ", "an edge: a range step off the slope beside it by more than this"}},
      {"mixed.max_incidence_deg", {"deg", "or, with no slope beside it, a step steeper than this incidence"}},
      {"mixed.max_run_rad", {"rad", "a run between two same-way edges no wider than this is mixed"}},
      {"mixed.max_missing", {"points", "missing returns in a row that still leave neighbours adjacent"}},
      {"normals.k_neighbours", {"points", "neighbours fitted for each normal and curvature"}},
      {"normals.orientation", {"-", "normal direction: viewpoint, propagate or none"}},
      {"normals.robust", {"-", "refit each normal with far-off neighbours down-weighted"}},
      {"segment", {"-", "find the sail among mast, boom, deck and walls (false: the cloud is the sail)"}},
      {"segmentation_voxel_sigmas", {"σ", "voxel size segmentation samples a denser scan at (0: every point)"}},
      {"working_voxel_sigmas", {"σ", "column width of the working resolution after segmentation (0: off)"}},
      {"working_column_depth_sigmas", {"σ", "a column whose samples spread deeper than this keeps them all"}},
      {"working_voxel_of_extent", {"× diagonal", "largest column width, as a fraction of the sail's diagonal"}},
      {"region_growing.k_neighbours", {"points", "neighbours a region grows through"}},
      {"region_growing.max_normal_angle_deg", {"deg", "largest normal angle between neighbours in one region"}},
      {"region_growing.max_curvature", {"-", "largest curvature (surface variation) of a point that grows on"}},
      {"region_growing.min_points", {"points", "smallest region kept"}},
      {"region_growing.max_points", {"points", "largest region kept"}},
      {"sail_pick.method", {"-", "which region is the sail: auto, seed (seed_point), index (cluster_index) or design (set by --design)"}},
      {"sail_pick.seed_point", {"m", "[x, y, z] of a point on the sail, for method seed"}},
      {"sail_pick.cluster_index", {"-", "region by size (0: largest), for method index"}},
      {"sail_pick.min_depth_m", {"m", "least camber depth of a sail (flatter: a wall)"}},
      {"sail_pick.min_depth_ratio", {"× extent", "least camber depth as a fraction of the region's extent"}},
      {"sail_pick.min_extent_m", {"m", "smallest extent of a sail"}},
      {"sail_pick.max_tilt_deg", {"deg", "largest tilt of a sail from vertical"}},
      {"sail_pick.min_width_ratio", {"× height", "least width of a sail for its height (a mast: 1 %)"}},
      {"find_spars", {"-", "remove round spars (mast, boom) beside the sail and give back its edge strip"}},
      {"spars.min_radius_m", {"m", "smallest spar radius"}},
      {"spars.max_radius_m", {"m", "largest spar radius"}},
      {"spars.min_length_radii", {"× radius", "least supported length of a spar"}},
      {"spars.min_arc_deg", {"deg", "least arc of the circumference its points span"}},
      {"spars.min_support", {"points", "least points on a spar"}},
      {"spars.hypotheses", {"-", "random two-point samples tried per spar"}},
      {"spars.max_spars", {"-", "most spars removed"}},
      {"spars.seed", {"-", "seed of the sampling (the same cloud gives the same spars)"}},
      {"statistical_outliers", {"-", "remove points far from their neighbours (statistical test)"}},
      {"statistical.k_neighbours", {"points", "neighbours whose mean distance is tested"}},
      {"statistical.std_ratio", {"std devs", "a point beyond mean + this × std of mean distances goes"}},
      {"radius_outliers", {"-", "remove points with too few neighbours within a radius"}},
      {"radius.radius_m", {"m", "the radius (0: 4 × the median nearest-neighbour spacing)"}},
      {"radius.min_neighbours", {"points", "fewer neighbours within the radius: the point goes"}},
      {"readmit_surface_points", {"-", "give back removed points that lie on the surface"}},
      {"readmit.k_neighbours", {"points", "kept neighbours the surface is fitted through"}},
      {"readmit.max_offset_m", {"m", "largest distance off that surface (0: 3 × sensor_sigma_m)"}},
      {"readmit.max_gap_factor", {"× spacing", "largest gap to the nearest kept point"}},
      {"readmit.passes", {"-", "readmission passes (each can reach further out)"}},
      {"smooth", {"-", "smooth the sail by moving least squares before meshing"}},
      {"smoothing.k_neighbours", {"points", "neighbourhood of each local fit"}},
      {"smoothing.reference_density_per_m2", {"points/m²", "denser than this, k grows with √density (0: k fixed)"}},
      {"smoothing.max_radius_ratio", {"× √area", "largest neighbourhood radius for the sail's size (0: no limit)"}},
      {"smoothing.adapt_to_noise", {"-", "a cloud quieter than the sensor takes smaller neighbourhoods"}},
      {"smoothing.polynomial_order", {"-", "local fit: 1 plane, 2 quadratic"}},
      {"smoothing.anchor_ratio", {"× radius", "spacing of shared fits inside the surface (0: a fit per point)"}},
      {"smoothing.good_m", {"m", "sensor random error σ (displacement class good)"}},
      {"smoothing.fair_m", {"m", "σ + systematic error (displacement class fair)"}},
      {"surface.projection", {"-", "2D domain of the mesh: plane, scan_angles or auto"}},
      {"surface.max_edge_m", {"m", "longest triangle edge kept (0: max_edge_factor × median edge)"}},
      {"surface.max_edge_factor", {"× median", "longest edge kept, in median Delaunay edge lengths"}},
      {"surface.largest_component_only", {"-", "keep only the largest connected piece of the mesh"}},
      {"outline.corners", {"-", "corners of the sail: 3, 4 (square top) or 0 for automatic"}},
      {"outline.corner_window_m", {"m", "arm of the turning angle at a corner (0: 1 % of the boundary)"}},
      {"outline.min_fourth_corner_deg", {"deg", "least turn of a fourth corner (corners 0)"}},
      {"outline.design_lengths_m", {"m", "[luff, leech, foot] of the design to check against (empty: none)"}},
      {"outline.design_tolerance", {"× length", "further off the design's lengths stops the analysis"}},
      {"outline.design_warning", {"× length", "further off (and beyond 3σ) is a warning"}},
      {"outline.beam_exit_diameter_m", {"m", "scanner beam's exit diameter, for the edges' footprint (0: none)"}},
      {"outline.beam_divergence_rad", {"rad", "scanner beam's full divergence, for the edges' footprint (0: none)"}},
      {"outline.edges_against_sky", {"-", "open sky behind the edges (a scan on the water): no footprint shift"}},
      {"outline.grazing_incidence_deg", {"deg", "a boundary the beams meet beyond this incidence is where the scan stopped"}},
      {"outline.scanner_max_range_m", {"m", "the scanner's range; a boundary there is where the scan stopped (0: unknown)"}},
      {"outline.scanner_position_sigma_m",
       {"m", "1σ of an estimated scanner position: both limits above are met 2σ sooner (0: the position is known)"}},
      {"sections.count", {"-", "sections at t = k/(count+1) of luff and leech"}},
      {"sections.fractions", {"× luff", "explicit section heights in (0, 1); override count"}},
      {"sections.plane", {"-", "section plane: normal, perpendicular or horizontal"}},
      {"sections.end_window", {"× chord", "chord fraction of the entry and exit angle fits"}},
      {"sections.peak_window", {"× chord", "± chord fraction of the fit at maximum camber"}},
      {"sections.normal_tolerance_deg", {"deg", "normal out of the section plane still accepted (plane normal)"}},
      {"sections.max_tilt_deg", {"deg", "largest rotation of the section plane about the chord"}},
      {"sections.max_iterations", {"-", "most rotations tried to hold the normal (plane normal)"}},
      {"sections.normal_radius", {"× chord", "chord fraction averaged for the surface normal"}},
      {"sections.noise_correlation_m", {"m", "length the curve's noise is correlated over (0: independent points)"}},
      {"sections.curve_points", {"points", "points of each output section curve"}},
      {"sections.max_bridged_gap", {"× chord", "widest hole inside the chord bridged by a cubic"}},
  };
  return notes;
}

// `text` followed by spaces up to `width` characters (UTF-8: "σ" and "×" take one column).
std::string padded(const std::string& text, size_t width) {
  size_t columns = 0;
  for (const char c : text) columns += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return text + std::string(width > columns ? width - columns : 0, ' ');
}

// Appends "key  value  unit  description" for every leaf of `doc` under `prefix`.
void describeLeaves(const nlohmann::json& doc, const std::string& prefix, std::string& out) {
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it.value().is_object()) {
      describeLeaves(it.value(), key, out);
      continue;
    }
    const auto note = paramNotes().find(key);
    const ParamNote n = note == paramNotes().end() ? ParamNote{"?", "(no description)"} : note->second;
    out += padded(key, 38) + " " + padded(it.value().dump(), 12) + " " + padded(n.unit, 10) + " " + n.description + "\n";
  }
}

}  // namespace

nlohmann::json paramsToJson(const AnalysisParams& params) { return params; }

std::string describeParams(const AnalysisParams& params) {
  std::string out;
  describeLeaves(paramsToJson(params), "", out);
  return out;
}

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
