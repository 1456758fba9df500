// Spectra of RGB inputs (docs/spectral.md "RGB upsampling"), each from the sRGB table
// (rgb_to_spectrum.hpp); `rgb` is linear sRGB.
//   RgbAlbedoSpectrum      a reflectance: the table's sigmoid of rgb clamped to [0, 1]; its
//                          values lie in [0, 1] (the sigmoid's range).
//   RgbUnboundedSpectrum   any non-negative rgb (an absorption, a scale > 1): m = max(rgb),
//                          s(lambda) = 2m sigmoid_{rgb / 2m}(lambda) (the table's input is kept
//                          at max 1/2, away from the sigmoid's saturated ends, as pbrt-v4 does).
//   RgbIlluminantSpectrum  an emitter's radiance: the unbounded spectrum times D65 at unit
//                          luminance (tabulated.hpp), so rgb (1, 1, 1) is D65 with Y = 1 and
//                          the film (xyz_estimator.hpp) turns an rgb emitter into that rgb up to
//                          the table's error; Mitsuba 3's spectral variants scale an sRGB emitter
//                          by D65 the same way.
#pragma once

#include "core/vec.hpp"
#include "spectral/rgb_to_spectrum.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"
#include "spectral/tabulated.hpp"

namespace pathlab {

class RgbAlbedoSpectrum {
public:
    RgbAlbedoSpectrum(const RgbToSpectrumTable& table, const Vec3f& rgb) : poly_(table(rgb)) {}
    float operator()(float lambda) const { return poly_(lambda); }
    Spectrum4 sample(const SampledWavelengths& wl) const {
        Spectrum4 s;
        for (int i = 0; i < kSpectrumLanes; ++i) s[i] = poly_(wl[i]);
        return s;
    }
    float max_value() const { return poly_.max_value(); }

private:
    SigmoidPolynomial poly_;
};

class RgbUnboundedSpectrum {
public:
    RgbUnboundedSpectrum(const RgbToSpectrumTable& table, const Vec3f& rgb) {
        const float m = std::max(std::max(rgb.x, rgb.y), rgb.z);
        scale_ = m > 0 ? 2 * m : 0;
        poly_ = table(scale_ > 0 ? rgb / scale_ : Vec3f(0.0f));
    }
    float operator()(float lambda) const { return scale_ * poly_(lambda); }
    Spectrum4 sample(const SampledWavelengths& wl) const {
        Spectrum4 s;
        for (int i = 0; i < kSpectrumLanes; ++i) s[i] = scale_ * poly_(wl[i]);
        return s;
    }
    float max_value() const { return scale_ * poly_.max_value(); }

private:
    float scale_ = 0;
    SigmoidPolynomial poly_;
};

class RgbIlluminantSpectrum {
public:
    RgbIlluminantSpectrum(const RgbToSpectrumTable& table, const Vec3f& rgb) : unbounded_(table, rgb) {}
    float operator()(float lambda) const { return unbounded_(lambda) * float(d65_unit_luminance(lambda)); }
    Spectrum4 sample(const SampledWavelengths& wl) const { return unbounded_.sample(wl) * sample_d65_unit_luminance(wl); }

private:
    RgbUnboundedSpectrum unbounded_;
};

// The same spectra at a path's 4 wavelengths, as spectral mode evaluates every RGB input
// (materials, media, emitters): a reflectance (RgbAlbedoSpectrum; a colour above 1 as
// RgbUnboundedSpectrum), any non-negative value (RgbUnboundedSpectrum) and an emitter's radiance
// (RgbIlluminantSpectrum). The table's lookups go through a direct-mapped per-thread cache keyed
// by the exact RGB bits, so a constant colour is looked up once per thread (a hit pays the
// 4-lane sigmoid only) and a textured one per hit; the cache returns exactly what the lookup
// would, so images do not depend on threads.
Spectrum4 reflectance_spectrum(const Rgb& rgb, const SampledWavelengths& wl);
Spectrum4 unbounded_spectrum(const Rgb& rgb, const SampledWavelengths& wl);
Spectrum4 illuminant_spectrum(const Rgb& rgb, const SampledWavelengths& wl);

}  // namespace pathlab
