// `sailshape design new` and `sailshape design show`: parametric design sails
// written as meshes, and any design file's dimensions and section parameters.
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/io/design_import.hpp"
#include "analysis/io/mesh_io.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"
#include "cli/sail_design.hpp"

namespace sailshape::cli {
namespace {

struct NewOptions {
  std::string type;
  double luff = 0, leech = 0, foot = 0, head_width = 0;  // 0: the type's example value
  double rake = -1, luff_round = -1, luff_sag = -1, leech_round = -1;
  std::vector<double> tack;
  std::vector<double> camber, draft, twist, entry, exit;  // foot, mid, head
  bool starboard = false, ascii = false;
  int rows = 120, columns = 60, sections = 3;
  std::string out;
};

struct ShowOptions {
  std::string input, unit = "auto", axes = "auto", json_out;
  int sections = 3, corners = 0;
};

// Sets stations[k].*field from values (one per foot/mid/head station).
template <class Field>
void setProfile(SailDesign& d, const std::vector<double>& values, Field field, const char* option) {
  if (values.empty()) return;
  if (values.size() != d.stations.size())
    throw InvalidInput(std::string("design new: ") + option + " takes " + std::to_string(d.stations.size()) +
                       " values (foot, mid, head), got " + std::to_string(values.size()));
  for (size_t k = 0; k < values.size(); ++k) d.stations[k].*field = values[k];
}

void runNew(const NewOptions& o) {
  SailDesign d = exampleDesign(parseSailType(o.type));
  if (o.luff > 0) d.luff_m = o.luff;
  if (o.leech > 0) d.leech_m = o.leech;
  if (o.foot > 0) d.foot_m = o.foot;
  if (o.head_width > 0) d.head_width_m = o.head_width;
  if (o.rake >= 0) d.rake_deg = o.rake;
  if (o.luff_round >= 0) d.luff_round_m = o.luff_round;
  if (o.luff_sag >= 0) d.luff_sag_m = o.luff_sag;
  if (o.leech_round >= 0) d.leech_round_m = o.leech_round;
  if (!o.tack.empty()) d.tack = Vec3(o.tack[0], o.tack[1], o.tack[2]);
  d.leeward_port = !o.starboard;
  setProfile(d, o.camber, &ProfileStation::camber_pct, "--camber-pct");
  setProfile(d, o.draft, &ProfileStation::draft_pct, "--draft-pct");
  setProfile(d, o.twist, &ProfileStation::twist_deg, "--twist-deg");
  setProfile(d, o.entry, &ProfileStation::entry_factor, "--entry");
  setProfile(d, o.exit, &ProfileStation::exit_factor, "--exit");
  const SailSurface surface(d);  // validates
  const Mesh mesh = generateSailMesh(d, o.rows, o.columns);
  const std::string ext = o.out.size() >= 4 ? o.out.substr(o.out.size() - 4) : "";
  MeshFormat format = MeshFormat::Auto;
  if (o.ascii) format = ext == ".stl" ? MeshFormat::StlAscii : ext == ".ply" ? MeshFormat::PlyAscii : MeshFormat::Auto;
  writeMesh(o.out, mesh, format);
  std::printf("wrote %s: %s, luff %.3f m, leech %.3f m, foot %.3f m", o.out.c_str(), sailTypeName(d.type).c_str(),
              d.luff_m, d.leech_m, d.foot_m);
  if (d.type == SailType::SquareTopMain) std::printf(", head width %.3f m", d.head_width_m);
  std::printf("; %zu triangles, area %.2f m2\n", mesh.triangles.size(), meshArea(mesh));
  std::printf("Design sections (known by construction):\n%8s %9s %9s %8s %10s %10s %9s\n", "height", "chord m",
              "camber %", "draft %", "twist deg", "entry deg", "exit deg");
  for (int k = 1; k <= o.sections; ++k) {
    const KnownSection s = surface.section(static_cast<double>(k) / (o.sections + 1));
    std::printf("%7.0f%% %9.3f %9.2f %8.1f %10.2f %10.1f %9.1f\n", 100 * s.fraction, s.chord_m, s.camber_pct,
                s.draft_pct, s.twist_deg, s.entry_deg, s.exit_deg);
  }
}

void runShow(const ShowOptions& o) {
  DesignImportOptions io;
  io.unit = o.unit;
  io.axes = o.axes;
  const DesignImport design = importDesign(o.input, io);
  OutlineParams op;
  op.corners = o.corners;
  SectionParams sp;
  sp.count = o.sections;
  sp.sensor_sigma_m = 0;  // a design has no measurement noise
  printDesignReport(o.input, design, analyzeMeshSections(design.mesh, op, sp), o.json_out);
}

}  // namespace

void printDesignReport(const std::string& input, const DesignImport& design, const MeshSections& a,
                       const std::string& json_out) {
  const SailOutline& ol = a.outline;
  if (!json_out.empty()) {
    nlohmann::json doc;
    auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
    doc["input"] = input;
    doc["format"] = design.format;
    doc["unit"] = design.unit;
    doc["axes"] = design.axes;
    doc["notes"] = design.notes;
    doc["faces"] = design.faces_read;
    doc["triangles"] = design.mesh.triangles.size();
    doc["vertices"] = design.mesh.vertices.size();
    doc["sail"] = {{"tack", vec(ol.tack)},
                   {"clew", vec(ol.clew)},
                   {"head", vec(ol.head)},
                   {"luff_length_m", ol.luff_length_m},
                   {"leech_length_m", ol.leech_length_m},
                   {"foot_length_m", ol.foot_length_m},
                   {"luff_straight_m", (ol.head - ol.tack).norm()},
                   {"leech_straight_m", ((ol.has_peak ? ol.peak : ol.head) - ol.clew).norm()},
                   {"foot_straight_m", (ol.clew - ol.tack).norm()},
                   {"area_m2", meshArea(design.mesh)}};
    if (ol.has_peak) {
      doc["sail"]["peak"] = vec(ol.peak);
      doc["sail"]["top_length_m"] = ol.top_length_m;
    }
    doc["sections"] = nlohmann::json::array();
    for (const Section& s : a.sections.sections) {
      nlohmann::json j = sectionParametersToJson(s.value);
      j["fraction"] = s.fraction;
      doc["sections"].push_back(j);
    }
    doc["warnings"] = ol.warnings;
    for (const auto& w : a.sections.warnings) doc["warnings"].push_back(w);
    writeJsonFile(json_out, doc);
    std::fprintf(stderr, "wrote %s\n", json_out.c_str());
    return;
  }
  std::printf("Design %s (%s): %zu faces, %zu triangles, %zu vertices\n", input.c_str(), design.format.c_str(),
              design.faces_read, design.mesh.triangles.size(), design.mesh.vertices.size());
  for (const auto& n : design.notes) std::printf("  %s\n", n.c_str());
  auto corner = [](const char* name, const Vec3& p) {
    std::printf("  %-5s (%8.3f, %8.3f, %8.3f) m\n", name, p.x(), p.y(), p.z());
  };
  std::printf("Corners (boat frame):\n");
  corner("tack", ol.tack);
  corner("clew", ol.clew);
  corner("head", ol.head);
  if (ol.has_peak) corner("peak", ol.peak);
  const Vec3 top = ol.has_peak ? ol.peak : ol.head;
  std::printf("Edges (along the edge / straight corner to corner):\n");
  std::printf("  luff  %.4f m / %.4f m\n  leech %.4f m / %.4f m\n  foot  %.4f m / %.4f m\n", ol.luff_length_m,
              (ol.head - ol.tack).norm(), ol.leech_length_m, (top - ol.clew).norm(), ol.foot_length_m,
              (ol.clew - ol.tack).norm());
  if (ol.has_peak) std::printf("  top   %.4f m\n", ol.top_length_m);
  std::printf("  area  %.4f m2\n\n", meshArea(design.mesh));
  std::printf("%8s %9s %9s %8s %10s %10s %10s %9s\n", "height", "chord m", "camber %", "draft %", "twist deg",
              "twist rel", "entry deg", "exit deg");
  for (const Section& s : a.sections.sections) {
    const SectionParameters& v = s.value;
    std::printf("%7.0f%% %9.3f %9.2f %8.1f %10.2f %10.2f %10.1f %9.1f\n", 100 * s.fraction, v.chord_m, v.camber_pct,
                v.draft_pct, v.twist_deg, v.twist_rel_deg, v.entry_deg, v.exit_deg);
  }
  std::vector<std::string> warnings = ol.warnings;
  warnings.insert(warnings.end(), a.sections.warnings.begin(), a.sections.warnings.end());
  if (!warnings.empty()) {
    std::printf("\nWarnings:\n");
    for (const auto& w : warnings) std::printf("  %s\n", w.c_str());
  }
}

void addDesignCommand(CLI::App& app) {
  CLI::App* design = app.add_subcommand(
      "design",
      "Generate a parametric design sail (new) or report on a design file (show)\n\n"
      "Design sails: generate a parametric design mesh (new), or read any design file and report its "
      "dimensions and section parameters (show).");
  design->require_subcommand(1);

  auto n = std::make_shared<NewOptions>();
  CLI::App* cmd = design->add_subcommand(
      "new",
      "Generate a parametric design sail and write it as a mesh\n\n"
      "Generate a parametric design sail in the boat frame (+X forward, +Y port, +Z up, metres) and write it as a "
      "mesh. Unset options take the type's example values; profiles are given at the foot, mid-height and head "
      "and interpolated smoothly in between.");
  cmd->add_option("--type", n->type, "Sail type: main, square-top, jib or gennaker")
      ->required()
      ->check(CLI::IsMember({"main", "square-top", "jib", "gennaker"}));
  cmd->add_option("--luff", n->luff, "Luff length M, straight tack to head, metres")->check(CLI::PositiveNumber);
  cmd->add_option("--leech", n->leech, "Leech length M, straight clew to head (peak for square tops), metres")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--foot", n->foot, "Foot length M, straight tack to clew, metres")->check(CLI::PositiveNumber);
  cmd->add_option("--head-width", n->head_width, "Head width M, head to peak (square-top only), metres")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--tack", n->tack, "Tack position X,Y,Z in the boat frame, metres")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--rake-deg", n->rake, "Luff tilt aft from vertical, degrees")->check(CLI::Range(0.0, 60.0));
  cmd->add_option("--luff-round", n->luff_round, "Luff curve forward at mid luff, metres (gennakers)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--luff-sag", n->luff_sag, "Luff sag to leeward at mid luff, metres (gennakers)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--leech-round", n->leech_round, "Roach: leech curve outwards at mid leech, metres")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--camber-pct", n->camber, "Camber (maximum depth, % of chord) at foot,mid,head, e.g. 9,11,8")
      ->delimiter(',');
  cmd->add_option("--draft-pct", n->draft, "Draft (position of maximum depth from the luff, % of chord) at "
                                           "foot,mid,head, e.g. 45,45,50")
      ->delimiter(',');
  cmd->add_option("--twist-deg", n->twist, "Chord angle to the centreline at foot,mid,head, degrees, e.g. 8,14,22")
      ->delimiter(',');
  cmd->add_option("--entry", n->entry, "Entry factor at foot,mid,head: luff slope = factor x camber / draft "
                                       "(2 = parabolic), in (0, 3]")
      ->delimiter(',');
  cmd->add_option("--exit", n->exit, "Exit factor at foot,mid,head: leech slope = factor x camber / (1 - draft), "
                                     "in (0, 3]")
      ->delimiter(',');
  cmd->add_flag("--starboard", n->starboard, "Camber and twist to starboard (-Y; port tack) instead of port (+Y)");
  cmd->add_option("--rows", n->rows, "Mesh rows from foot to head")->check(CLI::Range(2, 2000))->capture_default_str();
  cmd->add_option("--columns", n->columns, "Mesh columns from luff to leech")
      ->check(CLI::Range(2, 2000))
      ->capture_default_str();
  cmd->add_option("--sections", n->sections, "Sections in the printed table of known parameters")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_flag("--ascii", n->ascii, "Write ASCII STL or PLY instead of binary (OBJ is always text)");
  cmd->add_option("--out", n->out, "Output mesh: FILE.obj, FILE.stl or FILE.ply")->required();
  cmd->callback([n] { runNew(*n); });

  auto s = std::make_shared<ShowOptions>();
  CLI::App* show = design->add_subcommand(
      "show",
      "Report a design file's corners, edge lengths, area and section parameters\n\n"
      "Read a design (.dxf 3DFACE as Sailcut CAD exports it, .obj, .stl, .ply), bring it into the boat frame in "
      "metres, and report what was assumed, its corners, edge lengths, area and per-section parameters.");
  show->add_option("FILE", s->input, "Design file: .dxf, .obj, .stl or .ply")->required();
  addDesignFileOptions(show, s->unit, s->axes);
  show->add_option("--sections", s->sections, "Number of sections N, at t = k/(N+1) of luff and leech")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  show->add_option("--corners", s->corners, "Corners of the sail: 3, 4 (square top) or 0 for automatic")
      ->check(CLI::IsMember({0, 3, 4}))
      ->capture_default_str();
  show->add_option("--json", s->json_out, "Write the result as JSON to this file instead of the table");
  show->callback([s] { runShow(*s); });
}

}  // namespace sailshape::cli
