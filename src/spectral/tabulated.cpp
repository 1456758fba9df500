#include "spectral/tabulated.hpp"

#include "spectral/dense_spectrum.hpp"

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
    // At every nm (core's 5 nm table is linear between knots that are among them, so this is the
    // same function to float rounding), one index per lane.
    static const DenseSpectrum dense([](double l) { return d65_unit_luminance(l); });
    return dense.sample(wl);
}

}  // namespace pathlab
