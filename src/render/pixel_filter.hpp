// Reconstruction filters on the film (core/reconstruction_filter.hpp gives f), with samples
// spread into neighbouring pixels deterministically and a standard error that stays exact.
//
// How a pass is filtered. Every pass puts one sample in every pixel, all at the same offset
// u in [0, 1)^2 from their pixel's corner: pixel p's sample is at p + u (a lattice shifted by
// u, a pure function of (seed, pass); a pass is still independent of every other). Pixel q
// (centre c_q = q + 1/2) then takes
//     V_q = sum over pixels p of g_q(p + u) L_p,  with  g_q(x) = f(x - c_q) / D_q(u),
//     D_q(u) = sum over pixels p inside the image of f(p + u - c_q)
// (separable: f and D are products of their x and y parts). The weights of a pass sum to 1
// for every pixel, so a flat region stays exactly flat whatever the shift (there is no noise
// from the weights), and a border pixel is normalised by the weight inside the image. Splats
// at a raster position r (light tracing) go to pixel q with the same g_q(r), u = frac(r).
// In the interior D_q(u) is the filter's periodic sum: 1 for box, tent, mitchell and
// catmullrom (partitions of unity), within a few per cent of 1 for gaussian and lanczos.
//
// What a filtered pixel estimates: with u uniform, E[V_q] = integral over the image of
// g_q(x) L(x) dx, the image convolved with the filter (renormalised per shift, g_q = f where
// D = 1). Passes are independent, so the film's standard error over passes is the exact
// standard error of that estimate. Neighbouring pixels share samples (and, within a pass, the
// shift), so their errors are correlated: the error of a sum over pixels is not the root sum
// of squares of theirs. box with radius 1/2 is the film as it is (each sample in its pixel).
#pragma once

#include <vector>

#include "core/reconstruction_filter.hpp"
#include "core/vec.hpp"

namespace pathlab {

class PixelFilter {
public:
    PixelFilter(const FilterDesc& f, int width, int height);

    // True for box with radius 1/2: the plain film, no spreading.
    bool is_box() const { return plain_; }
    const FilterDesc& desc() const { return f_; }
    // The farthest pixel (in each axis) a sample reaches.
    int reach() const { return reach_; }

    // One pass: lattice[p] is pixel p's sample at p + shift; `out` gets every pixel's V_q.
    void filter_pass(const std::vector<Vec3d>& lattice, const Vec2f& shift, std::vector<Vec3d>& out) const;
    // Adds `value` splatted at raster position r (inside the image) to `out` (one per pixel).
    void splat(const Vec2f& r, const Vec3d& value, std::vector<Vec3d>& out) const;
    // g along one axis: the weight of a sample at coordinate x for pixel q (size pixels).
    double weight(int q, double x, int size) const;

private:
    // D along one axis for pixel q and shift u.
    double lattice_sum(int q, double u, int size) const;

    FilterDesc f_;
    int width_, height_;
    bool plain_;
    int reach_;
};

}  // namespace pathlab
