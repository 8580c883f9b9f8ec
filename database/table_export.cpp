#include "database/table_export.hpp"

#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string valueText(const Value& v) {
  if (std::holds_alternative<int64_t>(v)) return std::to_string(std::get<int64_t>(v));
  if (std::holds_alternative<double>(v)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", std::get<double>(v));  // round-trips
    return buf;
  }
  if (std::holds_alternative<std::string>(v)) return std::get<std::string>(v);
  return "";
}

}  // namespace

std::string tableToCsv(const Table& table) {
  std::string out;
  for (size_t c = 0; c < table.columns.size(); ++c) out += (c ? "," : "") + csvField(table.columns[c]);
  out += "\n";
  for (const auto& row : table.rows) {
    for (size_t c = 0; c < row.size(); ++c) out += (c ? "," : "") + csvField(valueText(row[c]));
    out += "\n";
  }
  return out;
}

nlohmann::ordered_json tableToJson(const Table& table) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const auto& row : table.rows) {
    nlohmann::ordered_json o = nlohmann::ordered_json::object();
    for (size_t c = 0; c < row.size() && c < table.columns.size(); ++c) {
      const Value& v = row[c];
      if (std::holds_alternative<int64_t>(v)) o[table.columns[c]] = std::get<int64_t>(v);
      else if (std::holds_alternative<double>(v)) o[table.columns[c]] = std::get<double>(v);
      else if (std::holds_alternative<std::string>(v)) o[table.columns[c]] = std::get<std::string>(v);
      else o[table.columns[c]] = nullptr;
    }
    rows.push_back(std::move(o));
  }
  return rows;
}

void writeTable(const std::string& path, const Table& table, const std::string& format) {
  if (format != "csv" && format != "json")
    throw InvalidInput("[writeTable] format must be csv or json (got \"" + format + "\")");
  const std::string text = format == "csv" ? tableToCsv(table) : tableToJson(table).dump(2) + "\n";
  std::ofstream out(path, std::ios::binary);
  if (!out) throw FileError(path + ": cannot open for writing");
  out << text;
  if (!out) throw FileError(path + ": write failed");
}

}  // namespace sailshape
