#include "database/copy.hpp"

#include <limits>
#include <map>
#include <variant>

#include "analysis/core/errors.hpp"
#include "database/dialect.hpp"
#include "database/schema.hpp"

namespace sailshape {
namespace {

// One sailshape table: its foreign keys (column, table) and, for tables that
// `append` merges, the columns that name a row.
struct TableSpec {
  const char* name;
  bool has_id;
  std::vector<std::pair<const char*, const char*>> refs;
  std::vector<const char*> natural_key;
  const char* order_by;
};

// Parents before children.
const std::vector<TableSpec>& tables() {
  static const std::vector<TableSpec> specs = {
      {"campaigns", true, {}, {"name"}, "id"},
      {"boats", true, {}, {"name"}, "id"},
      {"sails", true, {{"boat_id", "boats"}}, {"name"}, "id"},
      {"design_versions", true, {{"sail_id", "sails"}}, {"sail_id", "version"}, "id"},
      {"scanner_units", true, {}, {"serial"}, "id"},
      {"calibrations", true, {{"unit_id", "scanner_units"}}, {}, "id"},
      {"sessions", true, {{"campaign_id", "campaigns"}}, {"campaign_id", "name"}, "id"},
      {"trim_steps", true, {{"session_id", "sessions"}, {"sail_id", "sails"}}, {"session_id", "sail_id", "test", "step_order"}, "id"},
      {"control_settings", false, {{"trim_step_id", "trim_steps"}}, {"trim_step_id", "name"}, "trim_step_id, name"},
      {"pressures", false, {{"trim_step_id", "trim_steps"}}, {"trim_step_id", "tap"}, "trim_step_id, tap"},
      {"scans", true, {{"trim_step_id", "trim_steps"}, {"unit_id", "scanner_units"}}, {}, "id"},
      {"registrations", true, {{"scan_id", "scans"}}, {}, "id"},
      {"analyses", true, {{"scan_id", "scans"}}, {}, "id"},
      {"sections", true, {{"analysis_id", "analyses"}}, {}, "id"},
      {"design_comparisons", true, {{"analysis_id", "analyses"}, {"sail_id", "sails"}}, {}, "id"},
  };
  return specs;
}

using Cell = std::variant<std::monostate, int64_t, double, std::string, std::vector<uint8_t>>;

Cell readCell(const Statement& s, int c) {
  if (s.isNull(c)) return std::monostate{};
  if (s.isInteger(c)) return s.columnInt(c);
  if (s.isFloat(c)) return s.columnDouble(c);
  if (s.isBlob(c)) return s.columnBlob(c);
  return s.columnText(c);
}

void bindCell(Statement& s, int index, const Cell& v) {
  if (const auto* i = std::get_if<int64_t>(&v)) s.bind(index, *i);
  else if (const auto* d = std::get_if<double>(&v)) s.bind(index, *d);
  else if (const auto* t = std::get_if<std::string>(&v)) s.bind(index, *t);
  else if (const auto* b = std::get_if<std::vector<uint8_t>>(&v)) s.bindBlob(index, *b);
  else s.bindNull(index);
}

int64_t rowCount(Database& db, const char* table) {
  Statement s = db.prepare(std::string("SELECT count(*) FROM ") + table);
  s.step();
  return s.columnInt(0);
}

// A consistent view of the source for the whole copy.
class Snapshot {
 public:
  explicit Snapshot(Database& db) : db_(db) { db_.beginSnapshot(); }
  ~Snapshot() { db_.rollback(); }
  Snapshot(const Snapshot&) = delete;
  Snapshot& operator=(const Snapshot&) = delete;

 private:
  Database& db_;
};

// Copies `spec`'s rows; `ids` maps each table's source ids to the destination's.
size_t copyTable(Database& source, Database& dest, const TableSpec& spec, bool append,
                 std::map<std::string, std::map<int64_t, int64_t>>& ids) {
  constexpr int kRowsPerRead = 200;  // bounds memory: a scan row carries its cloud
  size_t added = 0;
  int64_t after = std::numeric_limits<int64_t>::min();
  std::map<int64_t, int64_t>& own_ids = ids[spec.name];
  for (;;) {
    Statement read = source.prepare(std::string("SELECT * FROM ") + spec.name +
                                    (spec.has_id ? " WHERE id > ? ORDER BY id LIMIT " + std::to_string(kRowsPerRead)
                                                 : std::string(" ORDER BY ") + spec.order_by));
    if (spec.has_id) read.bind(1, after);
    std::vector<std::string> columns;
    std::vector<std::vector<Cell>> rows;
    for (int c = 0; c < read.columnCount(); ++c) columns.push_back(read.columnName(c));
    while (read.step()) {
      std::vector<Cell> row;
      for (int c = 0; c < static_cast<int>(columns.size()); ++c) row.push_back(readCell(read, c));
      rows.push_back(std::move(row));
    }
    if (rows.empty()) break;
    auto column = [&](const std::string& name) {
      for (size_t c = 0; c < columns.size(); ++c)
        if (columns[c] == name) return c;
      throw DatabaseError("[copyStore] " + source.path() + ": table " + spec.name + " has no column " + name);
    };
    const size_t id_column = spec.has_id ? column("id") : 0;
    // The destination's columns: all but the id when it is renumbered.
    std::string names, marks;
    std::vector<size_t> written;
    for (size_t c = 0; c < columns.size(); ++c) {
      if (append && spec.has_id && c == id_column) continue;
      names += (names.empty() ? "" : ", ") + columns[c];
      marks += marks.empty() ? "?" : ", ?";
      written.push_back(c);
    }
    Statement insert = dest.prepare(std::string("INSERT INTO ") + spec.name + "(" + names + ") VALUES (" + marks + ")" +
                                    (append && !spec.has_id ? " ON CONFLICT DO NOTHING" : ""));
    std::string where;
    for (const char* k : spec.natural_key) where += std::string(where.empty() ? " WHERE " : " AND ") + k + " = ?";
    for (auto& row : rows) {
      const int64_t source_id = spec.has_id ? std::get<int64_t>(row[id_column]) : 0;
      if (spec.has_id) after = source_id;
      for (const auto& [ref, parent] : spec.refs) {
        Cell& v = row[column(ref)];
        if (!append || !std::holds_alternative<int64_t>(v)) continue;
        const auto& map = ids[parent];
        const auto found = map.find(std::get<int64_t>(v));
        if (found == map.end())
          throw DatabaseError("[copyStore] " + source.path() + ": " + spec.name + "." + ref + " refers to a missing row of " +
                              parent + " (run `sailshape db check`)");
        v = found->second;
      }
      if (append && spec.has_id && !spec.natural_key.empty()) {
        Statement existing = dest.prepare(std::string("SELECT id FROM ") + spec.name + where);
        for (size_t k = 0; k < spec.natural_key.size(); ++k) bindCell(existing, int(k) + 1, row[column(spec.natural_key[k])]);
        if (existing.step()) {
          own_ids[source_id] = existing.columnInt(0);
          continue;
        }
      }
      for (size_t i = 0; i < written.size(); ++i) bindCell(insert, int(i) + 1, row[written[i]]);
      insert.run();
      insert.reset();
      ++added;
      if (append && spec.has_id) own_ids[source_id] = dest.lastInsertId();
    }
    if (!spec.has_id) break;
  }
  return added;
}

}  // namespace

CopyResult copyStore(Database& source, Database& dest, const CopyOptions& options) {
  if (source.path() == dest.path())
    throw InvalidInput("[copyStore] source and destination are the same store (" + source.path() + ")");
  for (Database* db : {&source, &dest})
    if (db->userVersion() != kSchemaVersion)
      throw DatabaseError("[copyStore] " + db->path() + ": schema version " + std::to_string(db->userVersion()) +
                          ", not this sailshape's " + std::to_string(kSchemaVersion) + " (open it with openSailDatabase)");
  CopyResult result;
  Snapshot snapshot(source);
  runTransaction(dest, [&] {
    result = CopyResult{};
    if (!options.append) {
      std::string held;
      int64_t total = 0;
      for (const TableSpec& spec : tables()) {
        const int64_t n = rowCount(dest, spec.name);
        if (n > 0) held += (held.empty() ? "" : ", ") + std::to_string(n) + " " + spec.name;
        total += n;
      }
      if (total > 0)
        throw InvalidInput("[copyStore] " + dest.path() + " is not empty (" + held +
                           "); copy into an empty store, or append to it");
    }
    std::map<std::string, std::map<int64_t, int64_t>> ids;
    for (const TableSpec& spec : tables()) {
      const size_t n = copyTable(source, dest, spec, options.append, ids);
      result.rows_added.emplace_back(spec.name, n);
      result.total_rows += n;
      if (spec.has_id && !options.append) {
        const std::string resync = detail::identityResync(dest.backend() == Backend::PostgreSQL, spec.name);
        if (!resync.empty()) dest.exec(resync);
      }
    }
  });
  return result;
}

}  // namespace sailshape
