// The irradiance cache: records and the lookup of those valid at a point, in a hashed grid of
// cubes; each record is listed in every cube its sphere of influence (radius a R) touches, so a
// lookup reads one cube. Interpolation (Ward 1988, with Ward and Heckbert's 1992 gradients):
//   E(x, n) = sum_i w_i (E_i + (n_i x n) . grad_r_i + (x - p_i) . grad_t_i) / sum_i w_i,
//   e_i = |x - p_i| / R_i + sqrt(1 - n . n_i),   w_i = 1/e_i - 1/a   over the records with e_i < a
// (Ward's weight 1/e_i, less 1/a so that it falls to 0 where the record stops being valid: no
// seam there), leaving out records in front of x ((x - p_i) . (n + n_i)/2 < -0.01 R_i, Ward's
// test); a record's extrapolation below zero counts as zero. Deterministic: a cube's records are
// visited in the order they were added.
#pragma once

#include <unordered_map>
#include <vector>

#include "integrators/cache/irradiance_record.hpp"

namespace pathlab {

class IrradianceCache {
public:
    // a: the error threshold; cell: the grid's cube size.
    IrradianceCache(float a = 0.2f, float cell = 1.0f, bool gradients = true) : a_(a), cell_(cell), gradients_(gradients) {}
    void reset(float a, float cell, bool gradients);

    void add(const IrradianceRecord& r);
    // Whether some record is valid at (x, n).
    bool covered(const Vec3f& x, const Vec3f& n) const;
    // The interpolated irradiance; false where no record is valid.
    bool interpolate(const Vec3f& x, const Vec3f& n, Rgb& E) const;

    // Neighbour clamping (Křivánek's book, after Tabellion and Lamorlette): R_i <= R_j + |p_i - p_j|
    // for the records j valid at p_i, so that a small record's neighbours do not reach over it;
    // in record order, then the grid is rebuilt.
    void clamp_to_neighbours();

    const std::vector<IrradianceRecord>& records() const { return records_; }
    size_t size() const { return records_.size(); }
    float error_threshold() const { return a_; }

private:
    uint64_t key(int x, int y, int z) const;
    // Calls f(record) for the records listed in the cube of x.
    template <typename F> void for_each_near(const Vec3f& x, F&& f) const;
    void insert(uint32_t index);

    float a_, cell_;
    bool gradients_;
    std::vector<IrradianceRecord> records_;
    std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
};

}  // namespace pathlab
