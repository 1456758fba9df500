// The wavelengths one camera path carries (hero wavelength sampling, Wilkie et al. 2014, as
// pbrt-v4 does): a hero wavelength drawn from the visible-wavelength density below and three
// companions at the same density, their primary samples u + i/4 (mod 1), so the four are
// stratified over the visible range and each one alone is distributed with that density.
//
// Density (pbrt-v4's, docs/spectral.md "Wavelength sampling"): over [360, 830] nm,
//   p(lambda) = a / (S cosh^2(a (lambda - 538)))        a = 0.0072 / nm,
//   S = tanh(a (830 - 538)) - tanh(a (360 - 538))      (so that p integrates to 1),
// a smooth bump that follows the sum of the colour matching functions; sampled by inverting its
// CDF in closed form: lambda = 538 + atanh(tanh(a (360 - 538)) + u S) / a.
//
// terminate_secondary() keeps the hero only (a dispersive interface, where the lanes' paths
// would part): the hero's pdf becomes p(lambda_0) / 4 and the others 0. The film's estimator
// (xyz_estimator.hpp) averages f(lambda_i) / pdf_i over the 4 lanes, a lane of pdf 0 counting
// 0, so the average becomes f(lambda_0) / p(lambda_0): still unbiased, since the hero alone is
// distributed with p.
#pragma once

#include <array>

#include "core/spectrum.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

// The visible range: core/spectrum.hpp's CIE tables' range.
inline constexpr double kVisibleMinWavelength = kCieMinWavelength, kVisibleMaxWavelength = kCieMaxWavelength;

// The visible-wavelength density above (per nm; 0 outside [360, 830]) and its inverse CDF.
double visible_wavelength_pdf(double lambda);
double sample_visible_wavelength(double u);

class SampledWavelengths {
public:
    // The hero at sample_visible_wavelength(u) and its companions at u + i/4 (mod 1); u in [0, 1).
    static SampledWavelengths sample_visible(double u);

    float operator[](int i) const { return lambda_[size_t(i)]; }
    // Every lane's density (per nm) as a spectrum: divide a lane's estimate by it.
    Spectrum4 pdf() const { return pdf_; }
    float pdf(int i) const { return pdf_[i]; }

    // Keep the hero wavelength only (see the top of this file). Idempotent.
    void terminate_secondary();
    bool secondary_terminated() const { return pdf_[1] == 0 && pdf_[2] == 0 && pdf_[3] == 0; }

private:
    std::array<float, kSpectrumLanes> lambda_{};
    Spectrum4 pdf_;
};

}  // namespace pathlab
