// Spectra to linear sRGB through the CIE 1931 2-degree standard observer: what Mitsuba's RGB
// mode does with a <spectrum> given as wavelength:value pairs, a spectral data file or a black
// body, kept here (not in the scene-file reader) so that a spectral renderer can reuse the
// observer and the illuminant.
//
// The conversion (docs/scene-format.md, "Spectra"):
//   XYZ = integral over [360, 830] nm of s(lambda) w(lambda) (xbar, ybar, zbar)(lambda) dlambda / N
//   rgb = M_XYZ->sRGB(D65) XYZ
// where s is the given spectrum, linearly interpolated between its samples and zero outside
// them (as Mitsuba 3 integrates it), and
//   - a reflectance (an albedo) is lit by D65: w = D65, N = integral of D65 ybar, so a flat
//     reflectance c gives Y = c and, D65 being sRGB's white, the grey (c, c, c); the result
//     is clamped to [0, 1];
//   - an illuminant (an emitter's radiance) is taken as it is: w = 1, N = integral of ybar,
//     so a flat spectrum c gives Y = c with the chromaticity of illuminant E (slightly pink
//     in sRGB) and the D65 spectrum gives white; negative results are clamped to 0;
//   - an unbounded quantity (a conductor's eta, k) as an illuminant, clamped to >= 0.
// The tables are the CIE's 5 nm data (x, y, z bar and D65 from 360 to 830 nm), interpolated
// linearly between their samples.
#pragma once

#include <string>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

inline constexpr double kCieMinWavelength = 360, kCieMaxWavelength = 830;

// The colour matching functions at `lambda` nm (0 outside [360, 830]), unnormalised (ybar peaks at 1).
Vec3d cie1931_xyz_bar(double lambda);
// The D65 illuminant's relative spectral power at `lambda` nm (100 at 560 nm; 0 outside [360, 830]).
double cie_d65(double lambda);
// Integral of ybar over [360, 830] nm (106.86 for the 5 nm table) and of D65 * ybar.
double cie_y_integral();
double cie_d65_y_integral();

// Linear sRGB (Rec. 709 primaries, D65 white) of a CIE XYZ colour, and back.
Vec3d xyz_to_linear_srgb(const Vec3d& xyz);
Vec3d linear_srgb_to_xyz(const Vec3d& rgb);

enum class SpectrumUse { Reflectance, Illuminant, Unbounded };

// A sampled spectrum: increasing wavelengths (nm) and their values.
struct SampledSpectrum {
    std::vector<double> wavelengths, values;
};

// Parses "400:0.1, 500:0.25, 600:0.5" (pairs separated by commas or spaces). Returns an empty
// string on success, else what is wrong (a malformed pair, fewer than two pairs, wavelengths
// not increasing, a value that is not finite).
std::string parse_spectrum_pairs(const std::string& text, SampledSpectrum& out);
// Parses a spectral data file's text (Mitsuba's .spd: one "wavelength value" per line, '#'
// comments); the same checks.
std::string parse_spectrum_file(const std::string& text, SampledSpectrum& out);

// The integral of the spectrum against the observer (the XYZ of the conversion above, before
// the matrix), and the linear sRGB colour with the clamping of `use`. `clamped`, if given, is
// set when a channel was clamped (an out-of-gamut colour).
Vec3d spectrum_to_xyz(const SampledSpectrum& s, SpectrumUse use);
Vec3d spectrum_to_linear_srgb(const SampledSpectrum& s, SpectrumUse use, bool* clamped = nullptr);
// The spectrum's value at `lambda` nm: linear between its samples, 0 outside them.
double spectrum_value(const SampledSpectrum& s, double lambda);
// Planck's law: a black body's spectral radiance at `lambda` nm and `kelvin`, W / (m^2 sr nm).
double planck(double lambda, double kelvin);
// A black body of `kelvin` (planck() above), sampled each nm over the CIE range.
SampledSpectrum blackbody_spectrum(double kelvin);

}  // namespace pathlab
