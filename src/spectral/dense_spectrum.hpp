// A spectrum tabulated at every nm of [360, 830] (float), read by linear interpolation at a
// path's wavelengths: what an emitter's black body, a measured metal or a scene file's spectrum
// becomes at scene build so that a hit pays one index computation per lane instead of Planck's
// law or a binary search (bench: `pathlab_bench spectral`). A piecewise-linear input whose knots
// are at whole nm (core's 5 nm CIE tables) is reproduced exactly (to float rounding), other
// piecewise-linear ones differ only within 1 nm of their knots, and a smooth one by at most
// max |f''| / 8 nm^2. 0 outside [360, 830].
#pragma once

#include <array>
#include <functional>

#include "core/spectrum.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

class DenseSpectrum {
public:
    static constexpr int kFirst = int(kCieMinWavelength), kLast = int(kCieMaxWavelength);

    DenseSpectrum() = default;
    explicit DenseSpectrum(const std::function<double(double)>& f);
    explicit DenseSpectrum(const SampledSpectrum& s);

    float operator()(float lambda) const {
        const float l = lambda - float(kFirst);
        if (!(l >= 0 && l <= float(kLast - kFirst))) return 0;
        const size_t k = size_t(l);
        const float f = l - float(k);
        return (1 - f) * v_[k] + f * v_[k + 1];
    }
    Spectrum4 sample(const SampledWavelengths& wl) const {
        Spectrum4 s;
        for (int i = 0; i < kSpectrumLanes; ++i) s[i] = (*this)(wl[i]);
        return s;
    }

private:
    std::array<float, kLast - kFirst + 2> v_{};  // one past the end, equal to the last, for lambda = 830
};

}  // namespace pathlab
