// A dense grid of voxel values (1 or 3 channels) over the unit cube [0, 1]^3, looked up with
// trilinear interpolation as Mitsuba 3's gridvolume does: voxel (i, j, k) holds the value at the
// centre of its cell, ((i + 0.5) / xres, (j + 0.5) / yres, (k + 0.5) / zres), and lookups
// between the outermost centres and the cube's faces take the edge values (clamp). Outside the
// cube there is nothing: lookups there are 0 (a medium's grid ends at its bounding box).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

struct VoxelGrid {
    std::array<int, 3> res{0, 0, 0};
    int channels = 1;          // 1 or 3
    std::vector<float> data;   // data[((z * yres + y) * xres + x) * channels + c], as in a .vol file
    bool nearest = false;      // nearest-neighbour lookups instead of trilinear ones

    size_t voxel_count() const { return size_t(res[0]) * size_t(res[1]) * size_t(res[2]); }
    float at(int x, int y, int z, int c) const {
        return data[((size_t(z) * size_t(res[1]) + size_t(y)) * size_t(res[0]) + size_t(x)) * size_t(channels) + size_t(c)];
    }
    Rgb voxel(int x, int y, int z) const {
        return channels == 1 ? Rgb(at(x, y, z, 0)) : Rgb(at(x, y, z, 0), at(x, y, z, 1), at(x, y, z, 2));
    }
    // The interpolated value at a point of the unit cube (0 outside it); one channel is
    // replicated into all three.
    Rgb lookup(const Vec3f& u) const;
    // The largest value of any channel over the voxels a lookup inside the box [lo, hi] of the
    // unit cube can reach (an interpolated value never exceeds it).
    float max_over(const Vec3f& lo, const Vec3f& hi) const;
    float max_value() const;
};

}  // namespace pathlab
