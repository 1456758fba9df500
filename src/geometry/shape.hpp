// Plain data of the two kinds of shapes: triangle meshes and exact spheres. A shape refers to
// its material and (if it emits) its radiance by value; nothing here knows about Embree.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/transform.hpp"
#include "core/vec.hpp"

namespace pathlab {

struct MeshDesc {
    std::string name;
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;  // per vertex, optional (empty: flat shading)
    std::vector<Vec2f> uvs;      // per vertex texture coordinates, optional
    std::vector<std::array<uint32_t, 3>> triangles;
    uint32_t material = 0;
    Rgb emission{0.0f};  // radiance of a one-sided area emitter on the winding-normal side
};

struct SphereDesc {
    Vec3f center;
    float radius = 1;
    uint32_t material = 0;
    bool flip_normals = false;  // normals point inwards
    Rgb emission{0.0f};         // radiance of a one-sided area emitter on the normal side
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
