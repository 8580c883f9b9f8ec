#pragma once
// Writing any query Table as CSV (RFC 4180, header row, NULL as empty) or JSON
// (an array of objects keyed by column, NULL as null).
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "database/queries.hpp"

namespace sailshape {

std::string tableToCsv(const Table& table);
nlohmann::ordered_json tableToJson(const Table& table);  // keys in column order
// Writes by extension or explicit format ("csv" or "json"); throws FileError / InvalidInput.
void writeTable(const std::string& path, const Table& table, const std::string& format);

}  // namespace sailshape
