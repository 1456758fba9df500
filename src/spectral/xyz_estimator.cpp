#include "spectral/xyz_estimator.hpp"

#include "core/spectrum.hpp"

namespace pathlab {

Vec3d spectral_sample_to_xyz(const Spectrum4& L, const SampledWavelengths& wl) {
    static const double inv_y_integral = 1 / cie_y_integral();
    Vec3d xyz(0.0);
    for (int i = 0; i < kSpectrumLanes; ++i) {
        const float pdf = wl.pdf(i);
        if (pdf == 0 || L[i] == 0) continue;
        xyz += cie1931_xyz_bar(wl[i]) * (double(L[i]) / double(pdf));
    }
    return xyz * (inv_y_integral / kSpectrumLanes);
}

Vec3d spectral_sample_to_linear_srgb(const Spectrum4& L, const SampledWavelengths& wl) {
    return xyz_to_linear_srgb(spectral_sample_to_xyz(L, wl));
}

}  // namespace pathlab
