// RGB -> smooth spectrum (Jakob and Hanika 2019): a table of sigmoid-polynomial coefficients
// (sigmoid_polynomial.hpp) over the sRGB cube, fitted by pathlab's own optimiser
// (rgb_optimiser.hpp) at build time: tools/make_rgb_table.cpp writes the table into the build
// tree and a generated source embeds it (CMakeLists.txt; docs/spectral.md gives the resolution,
// the generation time and the round-trip errors).
//
// Lookup: a grey r = g = b is exact, c = (0, 0, (r - 1/2) / sqrt(r (1 - r))) (sigma(c2) = r);
// otherwise, with m the largest channel, z = rgb[m], x = rgb[m+1] / z, y = rgb[m+2] / z
// (channels mod 3), the coefficients are interpolated trilinearly between the table's nodes
// (x and y uniform, z at rgb_table_z_nodes()).
#pragma once

#include <vector>

#include "core/vec.hpp"
#include "spectral/sigmoid_polynomial.hpp"

namespace pathlab {

class RgbToSpectrumTable {
public:
    // `coefficients`: 3 * res^3 triples laid out as fit_rgb_table() writes them (not copied).
    RgbToSpectrumTable(int res, const float* coefficients);

    // The coefficients of the reflectance whose colour is `rgb` (each channel clamped to [0, 1],
    // NaN taken as 0).
    SigmoidPolynomial operator()(const Vec3f& rgb) const;
    int resolution() const { return res_; }
    // The largest value over [360, 830] nm of any node spectrum of the two z slices that a lookup
    // of a colour whose largest channel is z interpolates between (every channel m, x and y):
    // since the lookup's coefficients are a convex combination of those nodes', this bounds
    // what it may return (greys aside, which are looked up in closed form).
    float max_node_value_around(float z) const;

    // The sRGB table built with pathlab (defined by the generated source).
    static const RgbToSpectrumTable& srgb();

private:
    // The lower of the two z slices around z, and the coefficients of node (m, k, j, i).
    int z_slice(float z) const;
    const float* node(int m, int k, int j, int i) const {
        return data_ + (((size_t(m) * size_t(res_) + size_t(k)) * size_t(res_) + size_t(j)) * size_t(res_) + size_t(i)) * 3;
    }

    int res_;
    const float* data_;
    std::vector<float> z_nodes_;
};

}  // namespace pathlab
