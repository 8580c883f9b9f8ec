#pragma once
// Exceptions thrown across the project. Messages name the function (or file)
// and the offending value: "[growRegions] k_neighbours must be >= 3 (got 0)".
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

}  // namespace sailshape
