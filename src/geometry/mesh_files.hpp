// Mesh files beyond OBJ: PLY (binary and ASCII, read by Assimp) and Mitsuba's serialized format
// (zlib-compressed shapes, several per file). Neither loader welds, reorders or drops vertices
// or faces: a mesh equals the same mesh written as OBJ triangle for triangle (polygons are
// split into fans (0, i, i + 1), as Mitsuba does).
#pragma once

#include <string>

#include "geometry/shape.hpp"
#include "geometry/shape_meshes.hpp"

namespace pathlab {

// Throws MeshLoadError naming the file for a missing, malformed or hostile file.
MeshDesc load_ply_mesh(const std::string& path);
// Shape number `shape_index` (0-based) of a Mitsuba .serialized file (format versions 3 and 4).
MeshDesc load_serialized_mesh(const std::string& path, int shape_index);
// Writes a mesh as a one-shape .serialized file (version 4; for tests and tools).
std::string serialized_mesh_bytes(const MeshDesc& mesh, bool double_precision = false);

}  // namespace pathlab
