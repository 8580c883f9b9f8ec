#pragma once
// Exceptions thrown across the project. Messages name the function (or file)
// and the offending value: "[growRegions] k_neighbours must be >= 3 (got 0)".
#include <cstdio>
#include <stdexcept>
#include <string>

namespace sailshape {

// A caller passed a value the function cannot work with.
struct InvalidInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A file could not be read or written, or its content is malformed.
struct FileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The data does not allow the requested result (no sail found, no boundary, ...).
struct AnalysisError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// `v` with `digits` decimals, for messages: formatFixed(0.0123) is "0.012".
inline std::string formatFixed(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof(b), "%.*f", digits, v);
  return b;
}

}  // namespace sailshape
