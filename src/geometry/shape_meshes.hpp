// Triangle meshes of the scene-file shapes in their canonical (Mitsuba) forms, and OBJ loading.
#pragma once

#include <stdexcept>
#include <string>

#include "geometry/shape.hpp"
#include "core/transform.hpp"

namespace pathlab {

struct MeshLoadError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

MeshDesc rectangle_mesh();  // [-1,1]^2 in the z = 0 plane, normal +z
MeshDesc cube_mesh();       // [-1,1]^3, outward normals
// The unit disk in the z = 0 plane, normal +z, as a fan of `segments` triangles; its area is
// (segments / 2) sin(2 pi / segments), 0.04% short of pi with the default 128.
MeshDesc disk_mesh(int segments = 128);
// The open unit tube (radius 1, z from 0 to 1) as `segments` flat sides with radial vertex normals.
MeshDesc cylinder_mesh(int segments = 128);

// Triangulated OBJ (tinyobjloader). Vertex normals are kept when every face has them;
// throws MeshLoadError naming the file for a missing file, a parse error, no faces, or a
// non-finite vertex.
MeshDesc load_obj_mesh(const std::string& path);

// Applies an affine transform to positions and normals (skipped for the identity, so meshes
// without a transform keep their exact floats). As in Mitsuba, the facing (winding) is not
// corrected for mirroring transforms.
void transform_mesh(MeshDesc& mesh, const Transform& t);
// Drops vertex normals (flat shading).
void use_face_normals(MeshDesc& mesh);
// Reverses the winding (and the vertex normals): the shape faces the other way.
void flip_mesh_normals(MeshDesc& mesh);

}  // namespace pathlab
