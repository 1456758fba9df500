#include "spectral/blackbody.hpp"

#include <cmath>

#include "core/spectrum.hpp"

namespace pathlab {

namespace {
constexpr double kWien = 2.897771955e-3;  // m K (CODATA 2018)
}

BlackbodySpectrum::BlackbodySpectrum(double kelvin)
    : kelvin_(kelvin), normalisation_(1 / planck(kWien / kelvin * 1e9, kelvin)) {}

double BlackbodySpectrum::peak_wavelength() const { return kWien / kelvin_ * 1e9; }

float BlackbodySpectrum::operator()(float lambda) const {
    return lambda > 0 ? float(planck(lambda, kelvin_) * normalisation_) : 0.0f;
}

Spectrum4 BlackbodySpectrum::sample(const SampledWavelengths& wl) const {
    Spectrum4 s;
    for (int i = 0; i < kSpectrumLanes; ++i) s[i] = (*this)(wl[i]);
    return s;
}

double blackbody_luminous_efficacy(double kelvin) {
    constexpr double kStefanBoltzmann = 5.670374419e-8;  // W m^-2 K^-4 (CODATA 2018)
    constexpr double kPi = 3.14159265358979323846;
    constexpr int steps = 4700;  // 0.1 nm midpoint rule
    const double h = (kCieMaxWavelength - kCieMinWavelength) / steps;
    double luminous = 0;
    for (int i = 0; i < steps; ++i) {
        const double l = kCieMinWavelength + (i + 0.5) * h;
        luminous += cie1931_xyz_bar(l).y * planck(l, kelvin) * h;
    }
    return 683 * luminous / (kStefanBoltzmann * std::pow(kelvin, 4) / kPi);
}

}  // namespace pathlab
