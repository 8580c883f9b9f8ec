#pragma once
// Triangle mesh files: PLY (ascii/binary), OBJ, STL (ascii/binary). Metres.
#include <string>

#include "analysis/core/mesh.hpp"

namespace sailshape {

enum class MeshFormat { Auto, PlyAscii, PlyBinary, Obj, StlAscii, StlBinary };

// Auto: binary PLY for .ply, OBJ for .obj, binary STL for .stl.
void writeMesh(const std::string& path, const Mesh& mesh, MeshFormat format = MeshFormat::Auto);

// Reads .ply, .obj or .stl (polygons are fan-triangulated; STL's duplicated
// vertices are merged when bit-identical). Throws FileError naming the file and
// line or byte on malformed, truncated or empty files, or indices out of range.
Mesh readMesh(const std::string& path);

}  // namespace sailshape
