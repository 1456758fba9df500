#include "media/majorant_grid.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

MajorantGrid MajorantGrid::build(const VoxelGrid& grid, float scale, int voxels_per_cell) {
    MajorantGrid m;
    for (int a = 0; a < 3; ++a) m.res[size_t(a)] = std::clamp((grid.res[size_t(a)] + voxels_per_cell - 1) / voxels_per_cell, 1, 64);
    m.sigma.resize(size_t(m.res[0]) * size_t(m.res[1]) * size_t(m.res[2]));
    for (int z = 0; z < m.res[2]; ++z)
        for (int y = 0; y < m.res[1]; ++y)
            for (int x = 0; x < m.res[0]; ++x) {
                const Vec3f lo(float(x) / float(m.res[0]), float(y) / float(m.res[1]), float(z) / float(m.res[2]));
                const Vec3f hi(float(x + 1) / float(m.res[0]), float(y + 1) / float(m.res[1]), float(z + 1) / float(m.res[2]));
                // A little above the maximum: float rounding of the interpolation weights and of
                // the scale must never put a lookup above its majorant.
                m.sigma[(size_t(z) * size_t(m.res[1]) + size_t(y)) * size_t(m.res[0]) + size_t(x)] =
                    grid.max_over(lo, hi) * scale * (1 + 1e-5f);
            }
    return m;
}

MajorantIterator MajorantIterator::single(float tmin, float tmax, float sigma) {
    MajorantIterator it;
    it.t_ = tmin;
    it.t_end_ = tmax;
    it.single_sigma_ = sigma;
    it.done_ = !(tmin < tmax);
    return it;
}

MajorantIterator::MajorantIterator(const MajorantGrid& grid, const Vec3f& o, const Vec3f& d, float tmin, float tmax)
    : grid_(&grid) {
    // Clip to the unit cube (slabs).
    float t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) {
            if (o[a] < 0 || o[a] > 1) return;
            continue;
        }
        const float inv = 1 / d[a];
        float tn = (0 - o[a]) * inv, tf = (1 - o[a]) * inv;
        if (tn > tf) std::swap(tn, tf);
        t0 = std::max(t0, tn);
        t1 = std::min(t1, tf);
    }
    if (!(t0 < t1)) return;
    t_ = t0;
    t_end_ = t1;
    done_ = false;
    const Vec3f p = o + d * t0;
    for (int a = 0; a < 3; ++a) {
        const int n = grid.res[size_t(a)];
        cell_[a] = std::clamp(int(p[a] * float(n)), 0, n - 1);
        if (d[a] > 0) {
            next_t_[a] = t0 + (float(cell_[a] + 1) / float(n) - p[a]) / d[a];
            delta_t_[a] = 1 / (float(n) * d[a]);
            step_[a] = 1;
            stop_[a] = n;
        } else if (d[a] < 0) {
            next_t_[a] = t0 + (float(cell_[a]) / float(n) - p[a]) / d[a];
            delta_t_[a] = -1 / (float(n) * d[a]);
            step_[a] = -1;
            stop_[a] = -1;
        } else {
            next_t_[a] = kInf;
            delta_t_[a] = kInf;
            step_[a] = 0;
            stop_[a] = -1;
        }
    }
}

bool MajorantIterator::next(MajorantSegment& seg) {
    if (done_) return false;
    if (!grid_) {
        seg = {t_, t_end_, single_sigma_};
        done_ = true;
        return true;
    }
    const int a = next_t_[0] < next_t_[1] ? (next_t_[0] < next_t_[2] ? 0 : 2) : (next_t_[1] < next_t_[2] ? 1 : 2);
    const float t_exit = std::min(t_end_, next_t_[a]);
    seg = {t_, t_exit, grid_->at(cell_[0], cell_[1], cell_[2])};
    t_ = t_exit;
    if (next_t_[a] >= t_end_) {
        done_ = true;
    } else {
        cell_[a] += step_[a];
        if (cell_[a] == stop_[a]) done_ = true;
        next_t_[a] += delta_t_[a];
    }
    return true;
}

}  // namespace pathlab
