// What the mesh fuzz targets (obj, ply, serialized) require of a mesh a reader returns: every
// index within its vertices, every position finite; a violation stops the fuzzer (__builtin_trap).
#pragma once

#include <cstdint>

#include "geometry/shape.hpp"

inline void check_usable_mesh(const pathlab::MeshDesc& m) {
    for (const auto& t : m.triangles)
        for (const uint32_t i : t)
            if (i >= m.positions.size()) __builtin_trap();
    for (const pathlab::Vec3f& p : m.positions)
        if (!pathlab::is_finite(p)) __builtin_trap();
}
