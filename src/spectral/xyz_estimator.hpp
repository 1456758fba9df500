// The film's estimator of one spectral sample's colour. With L_i the radiance carried by lane i
// at wavelength lambda_i of density pdf_i (sampled_wavelengths.hpp),
//   XYZ = (1/4) sum_i L_i (xbar, ybar, zbar)(lambda_i) / pdf_i  /  integral of ybar,
// a lane of pdf 0 (a terminated secondary wavelength) counting 0. Its mean is
//   integral of L(lambda) (xbar, ybar, zbar)(lambda) dlambda / integral of ybar,
// core/spectrum.hpp's spectrum_to_xyz(L, SpectrumUse::Illuminant): a flat L = c gives Y = c,
// and the D65-shaped illuminant of RgbIlluminantSpectrum gives its RGB back.
// The colour matching functions are core/spectrum's 5 nm CIE 1931 tables, interpolated linearly.
#pragma once

#include "core/vec.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

Vec3d spectral_sample_to_xyz(const Spectrum4& L, const SampledWavelengths& wl);
// The same, then CIE XYZ -> linear sRGB (core/spectrum.hpp's matrix), unclamped.
Vec3d spectral_sample_to_linear_srgb(const Spectrum4& L, const SampledWavelengths& wl);

}  // namespace pathlab
