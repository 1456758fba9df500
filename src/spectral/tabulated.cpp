#include "spectral/tabulated.hpp"

#include <vector>

namespace pathlab {

Spectrum4 sample_tabulated(const SampledSpectrum& s, const SampledWavelengths& wl) {
    Spectrum4 out;
    for (int i = 0; i < kSpectrumLanes; ++i) out[i] = float(spectrum_value(s, wl[i]));
    return out;
}

double d65_unit_luminance(double lambda) {
    static const double scale = cie_y_integral() / cie_d65_y_integral();
    return cie_d65(lambda) * scale;
}

Spectrum4 sample_d65_unit_luminance(const SampledWavelengths& wl) {
    // At every nm of [360, 830] (core's 5 nm table is linear between samples that are among
    // these, so linear interpolation of these is the same function), one index per lane.
    static const std::vector<float> dense = [] {
        std::vector<float> v;
        for (int l = int(kCieMinWavelength); l <= int(kCieMaxWavelength); ++l) v.push_back(float(d65_unit_luminance(l)));
        v.push_back(v.back());
        return v;
    }();
    Spectrum4 out;
    for (int i = 0; i < kSpectrumLanes; ++i) {
        const float l = wl[i] - float(kCieMinWavelength);
        if (!(l >= 0 && l <= float(kCieMaxWavelength - kCieMinWavelength))) continue;
        const size_t k = size_t(l);
        const float f = l - float(k);
        out[i] = (1 - f) * dense[k] + f * dense[k + 1];
    }
    return out;
}

}  // namespace pathlab
