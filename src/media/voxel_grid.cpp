#include "media/voxel_grid.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

Rgb VoxelGrid::lookup(const Vec3f& u) const {
    if (!(u.x >= 0 && u.x <= 1 && u.y >= 0 && u.y <= 1 && u.z >= 0 && u.z <= 1)) return Rgb(0.0f);
    if (nearest) {
        int i[3];
        for (int a = 0; a < 3; ++a) i[a] = std::min(res[a] - 1, int(u[a] * float(res[a])));
        return voxel(i[0], i[1], i[2]);
    }
    // Cell-centred samples: x = u res - 1/2 between voxels floor(x) and floor(x) + 1.
    int i0[3], i1[3];
    float f[3];
    for (int a = 0; a < 3; ++a) {
        const float x = u[a] * float(res[a]) - 0.5f;
        const float fl = std::floor(x);
        f[a] = x - fl;
        const int i = int(fl);
        i0[a] = std::clamp(i, 0, res[a] - 1);
        i1[a] = std::clamp(i + 1, 0, res[a] - 1);
    }
    const auto lerp = [](const Rgb& a, const Rgb& b, float t) { return a * (1 - t) + b * t; };
    const Rgb c00 = lerp(voxel(i0[0], i0[1], i0[2]), voxel(i1[0], i0[1], i0[2]), f[0]);
    const Rgb c10 = lerp(voxel(i0[0], i1[1], i0[2]), voxel(i1[0], i1[1], i0[2]), f[0]);
    const Rgb c01 = lerp(voxel(i0[0], i0[1], i1[2]), voxel(i1[0], i0[1], i1[2]), f[0]);
    const Rgb c11 = lerp(voxel(i0[0], i1[1], i1[2]), voxel(i1[0], i1[1], i1[2]), f[0]);
    return lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2]);
}

float VoxelGrid::max_over(const Vec3f& lo, const Vec3f& hi) const {
    int a0[3], a1[3];
    for (int a = 0; a < 3; ++a) {
        // Every voxel whose centre lies within one voxel of the box (both interpolation modes),
        // and a little more: a lookup a rounding error outside the box is covered too.
        a0[a] = std::clamp(int(std::floor(lo[a] * float(res[a]) - 0.501f)), 0, res[a] - 1);
        a1[a] = std::clamp(int(std::floor(hi[a] * float(res[a]) - 0.499f)) + 1, 0, res[a] - 1);
    }
    float m = 0;
    for (int z = a0[2]; z <= a1[2]; ++z)
        for (int y = a0[1]; y <= a1[1]; ++y)
            for (int x = a0[0]; x <= a1[0]; ++x)
                for (int c = 0; c < channels; ++c) m = std::max(m, at(x, y, z, c));
    return m;
}

float VoxelGrid::max_value() const {
    float m = 0;
    for (float v : data) m = std::max(m, v);
    return m;
}

}  // namespace pathlab
