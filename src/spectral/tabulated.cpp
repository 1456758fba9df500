#include "spectral/tabulated.hpp"

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
    Spectrum4 out;
    for (int i = 0; i < kSpectrumLanes; ++i) out[i] = float(d65_unit_luminance(wl[i]));
    return out;
}

}  // namespace pathlab
