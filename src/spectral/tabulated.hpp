// Tabulated spectra (core/spectrum.hpp's SampledSpectrum: a scene file's wavelength:value list
// or .spd file, a measured index) and the D65 illuminant, evaluated at a path's wavelengths.
#pragma once

#include "core/spectrum.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

// Linear between the samples, 0 outside them (as core/spectrum's conversions integrate it).
Spectrum4 sample_tabulated(const SampledSpectrum& s, const SampledWavelengths& wl);

// D65 scaled to luminance 1: D65(lambda) * integral(ybar) / integral(D65 ybar), so that its XYZ
// by xyz_estimator.hpp (or core's SpectrumUse::Illuminant) is D65's white point with Y = 1.
double d65_unit_luminance(double lambda);
Spectrum4 sample_d65_unit_luminance(const SampledWavelengths& wl);

}  // namespace pathlab
