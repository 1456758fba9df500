// What the spectral-mode tests share: a render in either mode, an image's mean with its standard
// error, and the film's expected colour of a spectrum by quadrature.
#pragma once

#include <cmath>
#include <string>

#include "render_helpers.hpp"
#include "spectral/rgb_spectra.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab::test {

inline RenderResult render_mode(const SceneDescription& d, bool spectral, int size, int spp, uint64_t seed, int max_depth = -1,
                                const std::string& algorithm = "pt-mis") {
    JobRequest request;
    request.algorithm = algorithm;
    request.spp = uint64_t(spp);
    request.max_depth = max_depth;
    request.width = request.height = size;
    request.seed = seed;
    request.spectral = spectral;
    RenderJob job(scene_choice_of(d), request);
    return job.run();
}

// The image's mean per channel and its standard error (pixels are independent samples).
struct ImageMean {
    Vec3d mean{0.0}, se{0.0};
};
inline ImageMean image_mean(const RenderResult& r) {
    const Image m = r.film.mean(), s = r.film.standard_error();
    ImageMean out;
    const double n = double(m.pixel_count());
    for (size_t i = 0; i < m.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            out.mean[c] += m[i][c] / n;
            out.se[c] += double(s[i][c]) * s[i][c];
        }
    for (int c = 0; c < 3; ++c) out.se[c] = std::sqrt(out.se[c]) / n;
    return out;
}

// The film's expected colour of a spectrum: the mean of spectral_sample_to_linear_srgb,
// integral of s (xbar, ybar, zbar) / integral of ybar, by the midpoint rule every 0.25 nm.
template <typename F>
Vec3d film_colour(F&& s) {
    Vec3d xyz(0.0);
    const double h = 0.25;
    for (double l = kVisibleMinWavelength + h / 2; l < kVisibleMaxWavelength; l += h) xyz += cie1931_xyz_bar(l) * (s(l) * h);
    return xyz_to_linear_srgb(xyz / cie_y_integral());
}

// Spectral mode's expected colour of a reflectance rho lit by an RGB emitter e, against RGB
// mode's rho e: the largest relative difference over the channels. This is the upsampling's
// whole error for a path of one reflection (and, with rho = 1, for an emitter seen directly).
inline double relative_upsampling_error(const Rgb& rho, const Rgb& e) {
    const RgbToSpectrumTable& table = RgbToSpectrumTable::srgb();
    const RgbAlbedoSpectrum r(table, rho);
    const RgbIlluminantSpectrum le(table, e);
    const Vec3d got = film_colour([&](double l) { return double(r(float(l))) * le(float(l)); });
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
        const double want = double(rho[c]) * e[c];
        if (want > 0) worst = std::max(worst, std::abs(got[c] - want) / want);
    }
    return worst;
}

}  // namespace pathlab::test
