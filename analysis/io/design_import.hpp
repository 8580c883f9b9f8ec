#pragma once
// Design shapes from files (SPEC §7): OBJ, STL, PLY meshes and DXF 3DFACE
// exports (what Sailcut CAD writes for "export 3D sail"), brought into the boat
// frame (+X forward, +Y port, +Z up) in metres. The importer says what it
// assumed and what it detected, so a user can correct it with the options.
#include <string>
#include <vector>

#include "analysis/core/mesh.hpp"

namespace sailshape {

struct DesignImportOptions {
  // "auto" (millimetres when the largest extent exceeds 100, metres otherwise), "m", "mm" or "cm".
  std::string unit = "auto";
  // "boat": the file is already +X forward, +Y port, +Z up.
  // "sailcut": X horizontal from tack to clew, Y up, Z depth (Sailcut CAD); mapped to
  //   boat (X, Y, Z) = (−x, z, y), a proper rotation that puts the tack forward of the clew.
  // "auto": sailcut for DXF; for meshes, sailcut when Y is the largest extent and Z the
  //   smallest (a Y-up file), boat otherwise.
  std::string axes = "auto";
};

struct DesignImport {
  Mesh mesh;                        // metres, boat frame
  std::string format;               // "dxf", "obj", "stl", "ply"
  std::string unit;                 // the unit applied: "m", "mm" or "cm"
  std::string axes;                 // the frame applied: "boat" or "sailcut"
  size_t faces_read = 0;            // faces in the file (a DXF quad counts once)
  // What was assumed or detected, one human-readable line each, e.g.
  // "unit: millimetres (detected: largest extent 1050 > 100)".
  std::vector<std::string> notes;
};

// DXF 3DFACE entities as they are in the file (file units and frame). A face
// whose 4th corner equals its 3rd is a triangle; otherwise the quad is split
// into two triangles. Identical corners are merged into one vertex; faces that
// collapse after merging are dropped. `faces_read`, when given, receives the
// number of 3DFACE entities. Throws FileError naming the file and the problem:
// binary DXF, no 3DFACE entity, a truncated entity, a non-numeric coordinate
// or group code (with its line number).
Mesh readDxf3dFaces(const std::string& path, size_t* faces_read = nullptr);

// Reads .dxf, .obj, .stl or .ply and brings the mesh into the boat frame in
// metres. Throws InvalidInput for an unknown unit or axes option, FileError for
// unreadable or unsupported files.
DesignImport importDesign(const std::string& path, const DesignImportOptions& options = {});

}  // namespace sailshape
