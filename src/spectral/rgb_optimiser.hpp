// The fit behind the RGB -> spectrum table (Jakob and Hanika 2019, section 4): for a target
// linear sRGB reflectance, the coefficients of the sigmoid polynomial (sigmoid_polynomial.hpp)
// whose spectrum, lit by D65 and seen by the CIE 1931 observer, has the target's colour,
// the difference measured in CIELAB (white point: D65's XYZ) and minimised by Gauss-Newton
// steps with Levenberg-Marquardt damping (the Jacobian is exact: the model is differentiated
// sample by sample). The table (rgb_to_spectrum.hpp) is filled by fit_rgb_table(), run at build
// time by tools/make_rgb_table.cpp.
#pragma once

#include <array>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

using SigmoidCoefficients = std::array<double, 3>;

struct RgbFit {
    SigmoidCoefficients c{};
    double residual = 0;  // Euclidean CIELAB distance to the target at the end
    int iterations = 0;
};

// Fits `rgb` (linear sRGB in [0, 1]) starting from `start`.
RgbFit fit_rgb_reflectance(const Vec3d& rgb, const SigmoidCoefficients& start);

// The linear sRGB colour of the sigmoid polynomial's reflectance under D65, by the optimiser's
// own quadrature (1 nm midpoint rule over [360, 830] nm of the interpolated CIE tables).
Vec3d sigmoid_reflectance_rgb(const SigmoidCoefficients& c);

// The table's scale nodes: z_k = smoothstep(smoothstep(k / (res - 1))), smoothstep(x) = x^2 (3 - 2x),
// dense near black and near 1, where the fit's coefficients change fastest.
std::vector<float> rgb_table_z_nodes(int res);

// The whole table: 3 * res^3 coefficient triples, laid out [max channel][z][y][x][3]; the colour
// of entry (m, k, j, i) has channel m = z_k, channel m+1 = x_i z_k, channel m+2 = y_j z_k (mod 3),
// x_i = i / (res - 1), y_j = j / (res - 1). Each (m, j, i) line in z starts from the fit at
// k = res / 5 (itself started from 0) and walks up and down, each fit starting from its
// neighbour's coefficients; lines run on `threads` threads (the result does not depend on it).
std::vector<float> fit_rgb_table(int res, int threads);

}  // namespace pathlab
