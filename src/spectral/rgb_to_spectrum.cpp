#include "spectral/rgb_to_spectrum.hpp"

#include <algorithm>
#include <cmath>

#include "spectral/rgb_optimiser.hpp"

namespace pathlab {

RgbToSpectrumTable::RgbToSpectrumTable(int res, const float* coefficients)
    : res_(res), data_(coefficients), z_nodes_(rgb_table_z_nodes(res)) {}

SigmoidPolynomial RgbToSpectrumTable::operator()(const Vec3f& in) const {
    Vec3f rgb;
    for (int c = 0; c < 3; ++c) rgb[c] = in[c] > 0 ? std::min(in[c], 1.0f) : 0.0f;  // NaN -> 0
    if (rgb.x == rgb.y && rgb.y == rgb.z) {
        const float r = rgb.x;
        if (r <= 0) return {0, 0, -INFINITY};
        if (r >= 1) return {0, 0, INFINITY};
        return {0, 0, (r - 0.5f) / std::sqrt(r * (1 - r))};
    }
    const int m = rgb.x >= rgb.y ? (rgb.x >= rgb.z ? 0 : 2) : (rgb.y >= rgb.z ? 1 : 2);
    const float z = rgb[m];
    const float scale = float(res_ - 1) / z;
    const float x = rgb[(m + 1) % 3] * scale, y = rgb[(m + 2) % 3] * scale;
    const int xi = std::min(int(x), res_ - 2), yi = std::min(int(y), res_ - 2);
    const int zi = z_slice(z);
    const float dx = x - float(xi), dy = y - float(yi);
    const float dz = (z - z_nodes_[size_t(zi)]) / (z_nodes_[size_t(zi) + 1] - z_nodes_[size_t(zi)]);
    const auto at = [&](int k, int j, int i, int a) { return node(m, k, j, i)[a]; };
    float c[3];
    for (int a = 0; a < 3; ++a) {
        const auto lerp = [](float t, float u, float v) { return (1 - t) * u + t * v; };
        const auto along_x = [&](int k, int j) { return lerp(dx, at(k, j, xi, a), at(k, j, xi + 1, a)); };
        const auto along_y = [&](int k) { return lerp(dy, along_x(k, yi), along_x(k, yi + 1)); };
        c[a] = lerp(dz, along_y(zi), along_y(zi + 1));
    }
    return {c[0], c[1], c[2]};
}

int RgbToSpectrumTable::z_slice(float z) const {
    return std::clamp(int(std::upper_bound(z_nodes_.begin(), z_nodes_.end(), z) - z_nodes_.begin()) - 1, 0, res_ - 2);
}

float RgbToSpectrumTable::max_node_value_around(float z) const {
    const int zi = z_slice(z);
    float largest = 0;
    for (int m = 0; m < 3; ++m)
        for (int k = zi; k <= zi + 1; ++k)
            for (int j = 0; j < res_; ++j)
                for (int i = 0; i < res_; ++i) {
                    const float* c = node(m, k, j, i);
                    largest = std::max(largest, SigmoidPolynomial{c[0], c[1], c[2]}.max_value());
                }
    return largest;
}

}  // namespace pathlab
