#include "spectral/xyz_estimator.hpp"

#include <array>
#include <vector>

#include "core/spectrum.hpp"

namespace pathlab {
namespace {

// (xbar, ybar, zbar) / (4 integral of ybar) at every nm of [360, 830]: core's 5 nm tables are
// linear between their samples, which are among these, so interpolating these linearly gives
// the same function (to rounding) with one index computation for the three.
struct DenseObserver {
    std::vector<std::array<double, 3>> v;
    DenseObserver() {
        const double scale = 1 / (cie_y_integral() * kSpectrumLanes);
        for (int l = int(kCieMinWavelength); l <= int(kCieMaxWavelength); ++l) {
            const Vec3d b = cie1931_xyz_bar(l) * scale;
            v.push_back({b.x, b.y, b.z});
        }
        v.push_back(v.back());  // so that lambda = 830 interpolates within the table
    }
};

}  // namespace

Vec3d spectral_sample_to_xyz(const Spectrum4& L, const SampledWavelengths& wl) {
    static const DenseObserver observer;
    double xyz[3] = {0, 0, 0};
    for (int i = 0; i < kSpectrumLanes; ++i) {
        const float pdf = wl.pdf(i);
        const double l = double(wl[i]) - kCieMinWavelength;
        if (pdf == 0 || L[i] == 0 || !(l >= 0 && l <= kCieMaxWavelength - kCieMinWavelength)) continue;
        const size_t k = size_t(l);
        const double f = l - double(k), w = double(L[i]) / double(pdf);
        const auto& a = observer.v[k];
        const auto& b = observer.v[k + 1];
        for (int c = 0; c < 3; ++c) xyz[c] += ((1 - f) * a[size_t(c)] + f * b[size_t(c)]) * w;
    }
    return {xyz[0], xyz[1], xyz[2]};
}

Vec3d spectral_sample_to_linear_srgb(const Spectrum4& L, const SampledWavelengths& wl) {
    return xyz_to_linear_srgb(spectral_sample_to_xyz(L, wl));
}

}  // namespace pathlab
