// Plain data of the two kinds of shapes: triangle meshes and exact spheres. A shape refers to
// its material and (if it emits) its radiance by value; nothing here knows about Embree.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/transform.hpp"
#include "core/vec.hpp"
#include "core/mesh_attributes.hpp"

namespace pathlab {

// The participating media on the two sides of a shape's surface (indices into the scene's
// media, -1 for none), as Mitsuba's interior/exterior: interior is the side the geometric normal
// points away from. A shape without media leaves the medium of a ray that crosses it as it
// was. An index-matched boundary (Mitsuba's null BSDF) does not scatter at all: only volpath
// sees it (as a change of medium); every other estimator's rays pass through it.
struct MediumInterface {
    int32_t interior = -1, exterior = -1;
    bool index_matched = false;

    bool changes_medium() const { return interior >= 0 || exterior >= 0; }
    // The medium on the side of direction w (geometric normal ng).
    int32_t medium_towards(const Vec3f& w, const Vec3f& ng) const { return dot(w, ng) > 0 ? exterior : interior; }
};

// How a mesh's surface coordinates uv are found at a hit: interpolated from its per-vertex
// `uvs`, or (a disk's triangle fan) computed from the hit point as Mitsuba 3's disk does.
enum class UvMap : unsigned char { Vertices, Disk };

struct MeshDesc {
    std::string name;
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;  // per vertex, optional (empty: flat shading)
    std::vector<Vec2f> uvs;      // per vertex texture coordinates, optional
    std::vector<std::array<uint32_t, 3>> triangles;
    uint32_t material = 0;
    Rgb emission{0.0f};  // radiance of a one-sided area emitter on the winding-normal side
    MediumInterface media{};
    UvMap uv_map = UvMap::Vertices;
    Transform to_world, to_object;  // UvMap::Disk: the unit disk's placement and its inverse
    std::string id = {}; // the shape's id ("" for none): names its emitter's parameters (diff/)
    MeshAttributes attributes = {};  // the file's extra vertex and face values (PLY), for mesh_attribute textures
};

struct SphereDesc {
    Vec3f center;
    float radius = 1;
    uint32_t material = 0;
    bool flip_normals = false;  // normals point inwards
    Rgb emission{0.0f};         // radiance of a one-sided area emitter on the normal side
    MediumInterface media{};
    // The world directions of the sphere's own x, y, z axes (its to_world's rotation), which
    // its uv parameterisation (the poles on z, u = 0 towards x) follows.
    std::array<Vec3f, 3> axes{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    std::string id = {};        // the shape's id ("" for none): names its emitter's parameters (diff/)
};

// A shapegroup: meshes that instances place, each instance by its own transform (Embree
// instancing: the group's triangles are stored once).
struct ShapeGroupDesc {
    std::string name;
    std::vector<MeshDesc> meshes;  // in the group's space; their materials are the scene's
};

struct InstanceDesc {
    uint32_t group = 0;
    Transform to_world;
};

}  // namespace pathlab
