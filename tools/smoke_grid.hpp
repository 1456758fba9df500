// The procedural smoke of scenes/smoke.xml: a plume rising from a round source, widening and
// thinning with height, broken up by a few octaves of value noise. Only + - * / and integer
// hashing (no libm), so the same grid comes out on every machine; tools/make_smoke.cpp writes
// it to scenes/volumes/smoke.vol and tests/test_volpath.cpp checks the committed file against it.
#pragma once

#include <algorithm>
#include <cstdint>

#include "media/voxel_grid.hpp"

namespace pathlab::tools {

// A hash of a lattice point to [0, 1).
inline float lattice_value(int x, int y, int z, uint32_t seed) {
    uint32_t h = uint32_t(x) * 0x8da6b343u ^ uint32_t(y) * 0xd8163841u ^ uint32_t(z) * 0xcb1ab31fu ^ seed * 0x9e3779b9u;
    h ^= h >> 15;
    h *= 0x2c1b3c6du;
    h ^= h >> 12;
    h *= 0x297a2d39u;
    h ^= h >> 15;
    return float(h >> 8) * 0x1p-24f;
}

// Value noise with smoothstep interpolation between lattice points, in [0, 1).
inline float value_noise(float x, float y, float z, uint32_t seed) {
    const auto fl = [](float v) { return int(v) - (v < float(int(v)) ? 1 : 0); };
    const int ix = fl(x), iy = fl(y), iz = fl(z);
    const auto smooth = [](float t) { return t * t * (3 - 2 * t); };
    const float fx = smooth(x - float(ix)), fy = smooth(y - float(iy)), fz = smooth(z - float(iz));
    const auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
    float c[2][2];
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            c[dz][dy] = lerp(lattice_value(ix, iy + dy, iz + dz, seed), lattice_value(ix + 1, iy + dy, iz + dz, seed), fx);
    return lerp(lerp(c[0][0], c[0][1], fy), lerp(c[1][0], c[1][1], fy), fz);
}

// res^3 voxels over the unit cube, z up; densities in [0, 1].
inline VoxelGrid smoke_grid(int res = 32) {
    VoxelGrid g;
    g.res = {res, res, res};
    g.channels = 1;
    g.data.resize(size_t(res) * size_t(res) * size_t(res));
    for (int k = 0; k < res; ++k)
        for (int j = 0; j < res; ++j)
            for (int i = 0; i < res; ++i) {
                const float x = (float(i) + 0.5f) / float(res), y = (float(j) + 0.5f) / float(res), z = (float(k) + 0.5f) / float(res);
                // Three octaves of noise, stretched upwards (the plume's streaks).
                float n = 0, amplitude = 0.5f, frequency = 4;
                for (int o = 0; o < 3; ++o) {
                    n += amplitude * value_noise(x * frequency, y * frequency, z * frequency * 0.6f, uint32_t(o + 1));
                    amplitude *= 0.5f, frequency *= 2;
                }
                // The plume's axis drifts with height, pushed by low-frequency noise.
                const float cx = 0.5f + 0.25f * (value_noise(0.5f, 0.5f, z * 2.5f, 11) - 0.5f) + 0.12f * z;
                const float cy = 0.5f + 0.25f * (value_noise(1.5f, 0.5f, z * 2.5f, 12) - 0.5f);
                const float radius = 0.14f + 0.26f * z;
                const float dx = x - cx, dy = y - cy;
                const float r2 = (dx * dx + dy * dy) / (radius * radius);
                // A soft column (1 - r^2)^2, fading in at the source and out towards the top.
                const float column = r2 < 1 ? (1 - r2) * (1 - r2) : 0;
                const float height = std::min(1.0f, z * 6) * (1 - z * z);
                g.data[(size_t(k) * size_t(res) + size_t(j)) * size_t(res) + size_t(i)] = column * height * std::max(0.0f, 1.6f * n - 0.25f);
            }
    // Densest voxel 1.
    const float top = g.max_value();
    for (float& v : g.data) v /= top;
    return g;
}

}  // namespace pathlab::tools
