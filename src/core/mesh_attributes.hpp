// Values a mesh file gives its vertices or faces beyond positions, normals and uv (Mitsuba 3's
// mesh attributes: a PLY's extra properties), read by mesh_attribute textures
// (textures/mesh_attribute.hpp). Names follow Mitsuba 3: "vertex_" or "face_" and the PLY
// property's name without its channel suffix (color_0, color_1, color_2 -> "vertex_color"; a
// single weight_0 or weight -> "face_weight"; r, g, b or red, green, blue -> "vertex_color").
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

struct MeshAttribute {
    std::string name;           // "vertex_color", "face_weight", ...
    bool per_face = false;      // one value per triangle (else one per triangle corner, interpolated)
    int channels = 1;           // 1 or 3
    // channels floats per triangle, or per corner (3 per triangle, in its vertex order: a vertex's
    // value repeated in every triangle that uses it), in the mesh's triangle order
    std::vector<float> values;

    // The value at a point of triangle `tri` with barycentrics (b1, b2) of its second and third
    // corners; one channel is replicated into all three.
    Rgb at(uint32_t tri, float b1, float b2) const {
        const auto value = [&](size_t item) {
            const float* x = values.data() + item * size_t(channels);
            return channels == 1 ? Rgb(x[0]) : Rgb(x[0], x[1], x[2]);
        };
        if (per_face) return value(tri);
        const size_t c = size_t(tri) * 3;
        return value(c) * (1 - b1 - b2) + value(c + 1) * b1 + value(c + 2) * b2;
    }
    float min_value() const {
        float m = values.empty() ? 0.0f : values[0];
        for (float v : values) m = std::min(m, v);
        return m;
    }
    float max_value() const {
        float m = values.empty() ? 0.0f : values[0];
        for (float v : values) m = std::max(m, v);
        return m;
    }
};

using MeshAttributes = std::vector<MeshAttribute>;

inline const MeshAttribute* find_attribute(const MeshAttributes& a, const std::string& name) {
    for (const MeshAttribute& x : a)
        if (x.name == name) return &x;
    return nullptr;
}

}  // namespace pathlab
