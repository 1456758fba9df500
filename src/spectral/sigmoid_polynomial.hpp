// Jakob and Hanika 2019, "A Low-Dimensional Function Space for Efficient Spectral Upsampling":
// a smooth spectrum in [0, 1] as a sigmoid of a quadratic,
//   s(lambda) = sigma(c0 t^2 + c1 t + c2),   sigma(x) = 1/2 + x / (2 sqrt(1 + x^2)),
// with t = (lambda - 360) / 470 the wavelength normalised to [0, 1] over the visible range
// (pathlab's coefficients are those of t, not of lambda in nm: the quadratic's three terms then
// stay of the coefficients' own magnitude in float; docs/spectral.md).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/spectrum.hpp"

namespace pathlab {

inline constexpr double kSigmoidLambdaMin = kCieMinWavelength, kSigmoidLambdaRange = kCieMaxWavelength - kCieMinWavelength;

inline float sigmoid(float x) {
    if (std::isinf(x)) return x > 0 ? 1.0f : 0.0f;
    return 0.5f + x / (2 * std::sqrt(1 + x * x));
}

struct SigmoidPolynomial {
    float c0 = 0, c1 = 0, c2 = 0;

    float poly(float lambda) const {
        const float t = (lambda - float(kSigmoidLambdaMin)) * float(1 / kSigmoidLambdaRange);
        return (c0 * t + c1) * t + c2;
    }
    float operator()(float lambda) const { return sigmoid(poly(lambda)); }
    // The largest value over [360, 830] nm: at an end or at the quadratic's vertex.
    float max_value() const {
        float m = std::max((*this)(360.0f), (*this)(830.0f));
        if (c0 != 0) {
            const float t = -c1 / (2 * c0);
            if (t > 0 && t < 1) m = std::max(m, sigmoid((c0 * t + c1) * t + c2));
        }
        return m;
    }
};

}  // namespace pathlab
