// Majorants of a grid medium: a coarse grid over its unit cube whose cells hold the largest
// extinction any lookup inside them can return (the maximum over the voxels that the
// interpolation reaches, over the channels), and a 3D DDA (Amanatides and Woo 1987) that walks
// a ray through those cells, giving the pieces of the ray with their majorant. Delta and ratio
// tracking sample tentative collisions against these piecewise constant majorants instead of one
// global bound, so sparse smoke does not pay for its densest voxel everywhere (as pbrt-v4's
// majorant grid does).
#pragma once

#include <array>
#include <vector>

#include "media/voxel_grid.hpp"

namespace pathlab {

struct MajorantGrid {
    std::array<int, 3> res{1, 1, 1};
    std::vector<float> sigma;  // per cell, already multiplied by the medium's scale

    // Cells of about `voxels_per_cell` voxels per axis (at most 64 per axis).
    static MajorantGrid build(const VoxelGrid& grid, float scale, int voxels_per_cell = 4);
    float at(int x, int y, int z) const { return sigma[(size_t(z) * size_t(res[1]) + size_t(y)) * size_t(res[0]) + size_t(x)]; }
};

// A piece [t0, t1) of a ray with a constant majorant.
struct MajorantSegment {
    float t0 = 0, t1 = 0;
    float sigma_maj = 0;
};

// Walks the ray o + t d (in the grid's unit space; t is whatever parameter the caller uses,
// affine maps keep it) through the cells of a majorant grid, within [tmin, tmax].
class MajorantIterator {
public:
    MajorantIterator() = default;  // no segments
    // One segment [tmin, tmax) with majorant sigma (homogeneous media).
    static MajorantIterator single(float tmin, float tmax, float sigma);
    MajorantIterator(const MajorantGrid& grid, const Vec3f& o, const Vec3f& d, float tmin, float tmax);

    bool next(MajorantSegment& seg);

private:
    const MajorantGrid* grid_ = nullptr;
    float t_ = 0, t_end_ = 0;
    float single_sigma_ = 0;
    bool done_ = true;
    int cell_[3] = {0, 0, 0}, step_[3] = {0, 0, 0}, stop_[3] = {0, 0, 0};
    float next_t_[3] = {0, 0, 0}, delta_t_[3] = {0, 0, 0};
};

}  // namespace pathlab
