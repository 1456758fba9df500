// Black-body emission (Planck's law, core/spectrum.hpp's planck()), normalised so that the
// spectrum's maximum over all wavelengths is 1 (as pbrt-v4's BlackbodySpectrum): the peak is at
// Wien's lambda_max = b / T, b = 2.897771955e-3 m K, so s(lambda) = B(lambda, T) / B(lambda_max, T).
// An emitter then sets its brightness with its own scale; the temperature sets only the colour.
#pragma once

#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

class BlackbodySpectrum {
public:
    explicit BlackbodySpectrum(double kelvin);
    float operator()(float lambda) const;
    Spectrum4 sample(const SampledWavelengths& wl) const;
    double kelvin() const { return kelvin_; }
    double peak_wavelength() const;  // nm

private:
    double kelvin_, normalisation_;
};

// Luminous efficacy of black-body radiation at `kelvin` (lm/W): K_m times the fraction of the
// whole radiance that the photopic luminosity function V = ybar passes,
//   683 lm/W * integral_{360}^{830} ybar(lambda) B(lambda, T) dlambda / (sigma T^4 / pi),
// with sigma the Stefan-Boltzmann constant (sigma T^4 / pi: the integral of B over all wavelengths).
double blackbody_luminous_efficacy(double kelvin);

}  // namespace pathlab
