#pragma once
// Point cloud files: PLY (ascii, binary little/big endian), PCD (ascii, binary),
// XYZ / CSV text. Coordinates in metres.
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"

namespace sailshape {

enum class CloudFormat { Auto, PlyAscii, PlyBinary, PcdAscii, PcdBinary, Xyz, Csv };

struct CloudReadResult {
  Cloud cloud;
  std::string format;                 // "ply-ascii", "ply-binary", "pcd-ascii", "pcd-binary", "xyz", "csv"
  size_t dropped_nan_points = 0;      // points with a NaN coordinate (invalid returns), dropped
  std::vector<std::string> warnings;  // e.g. "dropped 12 points with NaN coordinates"
};

// Reads a cloud; the format comes from the extension (.ply .pcd .xyz .txt .csv)
// and, for PLY/PCD, the header. Throws FileError naming the file and the line
// (text) or byte offset (binary) on a missing file, unknown extension, wrong or
// truncated header, truncated data, non-numeric values, infinite coordinates,
// or a file without any finite point. NaN points are dropped with a warning.
CloudReadResult readCloud(const std::string& path);

// Writes x y z plus intensity / alpha_rad / beta_rad when present; the viewpoint
// is kept (PCD VIEWPOINT, PLY comment), and in PLY a sweep's lost scan lines
// (Cloud::lost_beta_rad, "comment lost_beta_rad ..."). Auto picks binary PLY for .ply,
// binary PCD for .pcd, CSV for .csv and space-separated text for .xyz/.txt.
void writeCloud(const std::string& path, const Cloud& cloud, CloudFormat format = CloudFormat::Auto);

}  // namespace sailshape
