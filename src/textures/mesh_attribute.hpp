// mesh_attribute: a texture whose value is the mesh's own attribute at the hit (Mitsuba 3's
// mesh_attribute; mitsuba3 src/textures/mesh_attribute.cpp): a vertex attribute interpolated
// with the hit's barycentrics, or the hit face's value, times `scale`. The attributes come from
// the mesh file (core/mesh_attributes.hpp); a lookup needs the hit's triangle, so texture
// lookups take a SurfaceUv (uv, and on a mesh with attributes its triangle and barycentrics),
// which the other textures see as plain uv.
#pragma once

#include <string>

#include "core/mesh_attributes.hpp"

namespace pathlab {

// Where a texture is looked up: surface coordinates uv, and on a mesh that has attributes the
// attributes, the triangle and the barycentrics of its second and third corners.
struct SurfaceUv : Vec2f {
    const MeshAttributes* attributes = nullptr;
    uint32_t tri = 0;
    float b1 = 0, b2 = 0;

    SurfaceUv() : Vec2f(0.0f, 0.0f) {}
    SurfaceUv(const Vec2f& uv) : Vec2f(uv) {}
    SurfaceUv(float u, float v) : Vec2f(u, v) {}
};

struct MeshAttributeTexture {
    std::string name;  // "vertex_..." or "face_..."
    float scale = 1;

    // The scene file binds this texture only to shapes whose mesh has the attribute (with one
    // channel for a float parameter; read_shape.cpp): a lookup without it (a bug) is black.
    Rgb eval(const SurfaceUv& at) const {
        const MeshAttribute* a = at.attributes ? find_attribute(*at.attributes, name) : nullptr;
        return a ? a->at(at.tri, at.b1, at.b2) * scale : Rgb(0.0f);
    }
    float eval_1(const SurfaceUv& at) const { return eval(at).x; }
    // Varies across triangles in ways uv does not describe: no gradient in uv (a bump map of it is flat).
    Vec2f eval_1_grad(const SurfaceUv&) const { return {0.0f, 0.0f}; }
};

}  // namespace pathlab
