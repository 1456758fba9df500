#include "spectral/sampled_wavelengths.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {
namespace {

constexpr double kA = 0.0072, kMu = 538;

struct Cdf {
    double t0, s;  // tanh(a (360 - mu)) and the normaliser S
};
const Cdf& cdf() {
    static const Cdf c{std::tanh(kA * (kVisibleMinWavelength - kMu)),
                       std::tanh(kA * (kVisibleMaxWavelength - kMu)) - std::tanh(kA * (kVisibleMinWavelength - kMu))};
    return c;
}

}  // namespace

double visible_wavelength_pdf(double lambda) {
    if (!(lambda >= kVisibleMinWavelength && lambda <= kVisibleMaxWavelength)) return 0;
    const double c = std::cosh(kA * (lambda - kMu));
    return kA / (cdf().s * c * c);
}

double sample_visible_wavelength(double u) {
    const double l = kMu + std::atanh(cdf().t0 + u * cdf().s) / kA;
    return std::clamp(l, kVisibleMinWavelength, kVisibleMaxWavelength);
}

SampledWavelengths SampledWavelengths::sample_visible(double u) {
    // With x = tanh(a (lambda - mu)) = t0 + u S, lambda = mu + atanh(x) / a and, since
    // 1 / cosh^2 = 1 - tanh^2, p(lambda) = a (1 - x^2) / S: one logarithm per lane, no cosh.
    SampledWavelengths w;
    const Cdf& c = cdf();
    for (int i = 0; i < kSpectrumLanes; ++i) {
        double ui = u + double(i) / kSpectrumLanes;
        if (ui >= 1) ui -= 1;
        const double x = c.t0 + ui * c.s;
        const double l = std::clamp(kMu + 0.5 * std::log((1 + x) / (1 - x)) / kA, kVisibleMinWavelength, kVisibleMaxWavelength);
        w.lambda_[size_t(i)] = float(l);
        w.pdf_[i] = float(kA * (1 - x * x) / c.s);
    }
    return w;
}

void SampledWavelengths::terminate_secondary() {
    if (secondary_terminated()) return;
    pdf_[0] /= float(kSpectrumLanes);
    for (int i = 1; i < kSpectrumLanes; ++i) pdf_[i] = 0;
}

}  // namespace pathlab
