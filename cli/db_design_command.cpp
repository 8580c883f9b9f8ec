// `sailshape db design add|list|show|export`: a sail's design versions in the database.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "analysis/core/errors.hpp"
#include "analysis/io/mesh_io.hpp"
#include "cli/db_design_command.hpp"
#include "cli/commands.hpp"
#include "cli/sail_design.hpp"
#include "database/catalog.hpp"

namespace sailshape::cli {
namespace {

struct DesignOptions {
  std::string sail, file, unit = "auto", axes = "auto", json_out;
  int version = 0;  // 0: the current one
};

void runAdd(const DesignOptions& o, Database db) {
  // Read and checked before anything is written: a file that is no sail's design stores nothing.
  const DesignFile f = readDesignFile(o.file, o.unit, o.axes);
  const DesignImport& d = f.design;
  const int version = addDesignVersion(db, o.sail, d.mesh, {o.file, d.format, d.unit, d.axes});
  const SailOutline& ol = f.sections.outline;
  std::printf("stored %s as design version %d of sail \"%s\"%s: %s, %s, %s axes; luff %.3f m, leech %.3f m, foot %.3f m, "
              "area %.2f m2\n",
              o.file.c_str(), version, o.sail.c_str(), version > 1 ? " (now current; earlier versions kept)" : "",
              d.format.c_str(), d.unit.c_str(), d.axes.c_str(), ol.luff_length_m, ol.leech_length_m, ol.foot_length_m,
              meshArea(d.mesh));
}

void runList(const DesignOptions& o, Database db) {
  const std::vector<DesignVersion> versions = designVersions(db, o.sail);
  if (versions.empty()) {
    std::printf("sail \"%s\" has no design (store one with `sailshape db design add`)\n", o.sail.c_str());
    return;
  }
  std::printf("%-8s %-21s %-8s %-5s %-8s %9s %s\n", "version", "added", "format", "unit", "axes", "triangles", "file");
  auto text = [](const std::string& s) { return s.empty() ? "-" : s.c_str(); };  // not known: stored before versions
  for (const DesignVersion& v : versions)
    std::printf("%-8s %-21s %-8s %-5s %-8s %9zu %s\n", (std::to_string(v.version) + (v.current ? " *" : "")).c_str(),
                v.added_at.c_str(), text(v.source.format), text(v.source.unit), text(v.source.axes), v.triangles,
                text(v.source.file));
  std::printf("* current: reports, the viewer and imports use it\n");
}

// The stored version as `design show` reports a file.
void runShow(const DesignOptions& o, Database db) {
  const int version = o.version ? o.version : currentDesignVersion(db, o.sail);
  DesignImport d;
  d.mesh = designVersionMesh(db, o.sail, o.version);
  for (const DesignVersion& v : designVersions(db, o.sail))
    if (v.version == version) d.format = v.source.format, d.unit = v.source.unit, d.axes = v.source.axes;
  d.faces_read = d.mesh.triangles.size();
  d.notes.push_back("stored in metres, boat frame (as read with unit " + (d.unit.empty() ? "?" : d.unit) + ", axes " +
                    (d.axes.empty() ? "?" : d.axes) + ")");
  const std::string name = "\"" + o.sail + "\" version " + std::to_string(version);
  printDesignReport(name, d, designSections(d.mesh, {}), o.json_out);
}

void runExport(const DesignOptions& o, Database db) {
  const Mesh mesh = designVersionMesh(db, o.sail, o.version);
  writeMesh(o.file, mesh);
  std::printf("wrote design %s of sail \"%s\" to %s (%zu triangles, metres, boat frame)\n",
              o.version ? ("version " + std::to_string(o.version)).c_str() : "(current)", o.sail.c_str(), o.file.c_str(),
              mesh.triangles.size());
}

}  // namespace

void addDbDesignCommand(CLI::App* db, const std::function<void(CLI::App*)>& add_db,
                        const std::function<Database(const char*)>& open) {
  auto o = std::make_shared<DesignOptions>();
  CLI::App* design = db->add_subcommand(
      "design",
      "A sail's design versions: add one from a design file, list, show or export them\n\n"
      "A sail's design versions. `add` stores a design file (any format `sailshape design show` reads) for a sail "
      "as its next version, which becomes current: reports, the viewer, and scans imported for the sail use the "
      "current version. Earlier versions stay and can be shown or exported.");
  design->require_subcommand(1);
  auto sail = [&](CLI::App* cmd) { cmd->add_option("--sail", o->sail, "Sail name")->required(); };
  auto version = [&](CLI::App* cmd) {
    cmd->add_option("--version", o->version, "Design version (default: the current one; see db design list)")
        ->check(CLI::PositiveNumber);
  };

  CLI::App* add = design->add_subcommand(
      "add", "Store a design file as the sail's next design version (the sail is created when new)");
  add_db(add);
  sail(add);
  add->add_option("FILE", o->file, "Design file: .dxf (3DFACE, as Sailcut CAD exports it), .obj, .stl or .ply")->required();
  addDesignFileOptions(add, o->unit, o->axes);
  add->callback([o, open] { runAdd(*o, open("design add")); });

  CLI::App* list = design->add_subcommand("list", "List a sail's design versions, the current one marked");
  add_db(list);
  sail(list);
  list->callback([o, open] { runList(*o, open("design list")); });

  CLI::App* show = design->add_subcommand("show", "Report a stored design version as `sailshape design show` does a file");
  add_db(show);
  sail(show);
  version(show);
  show->add_option("--json", o->json_out, "Write the result as JSON to this file instead of the table");
  show->callback([o, open] { runShow(*o, open("design show")); });

  CLI::App* exp = design->add_subcommand("export", "Write a stored design version as a mesh (metres, boat frame)");
  add_db(exp);
  sail(exp);
  version(exp);
  exp->add_option("OUT", o->file, "Output mesh: FILE.obj, FILE.stl or FILE.ply")->required();
  exp->callback([o, open] { runExport(*o, open("design export")); });
}

}  // namespace sailshape::cli
