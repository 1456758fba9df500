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

// A room for the bidirectional and merging estimators' dispersion tests (size x size pixels): a
// ceiling light above the view behind a pane of strongly dispersive glass (Cauchy n = 1.5 +
// 0.04 / lambda^2, about ten times N-BK7's dispersion; two parallel interfaces 0.1 apart),
// lighting a floor and three bright walls (much light arrives after several bounces): the light
// subpaths (photons) that reach them are dispersed, and so is every path the light tracer splats
// but those of the light escaping past the pane's edge. pt-mis finds the light only by hitting it
// through the pane (its light samples are occluded by the glass). With `behind_glass` a second
// pane stands before the camera: every camera subpath is dispersed too, and every connection or
// merge joins two hero-only subpaths, where the factor 4 of terminate_secondary() counts once.
inline std::string dispersive_room(bool behind_glass, int size) {
    std::string text = R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="55"/>
    <transform name="to_world"><lookat origin="0, -4, 1.3" target="0, 0, 0.9" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="SIZE"/><integer name="height" value="SIZE"/><rfilter type="box"/></film></sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.65, 0.45"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="90"/><translate y="2" z="1.5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.7, 0.85"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate y="1" angle="90"/><translate x="-2" z="1.5"/></transform>
    <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.85, 0.8, 0.7"/></bsdf></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate y="1" angle="90"/><translate x="2" z="1.5"/></transform>
    <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.85, 0.8, 0.7"/></bsdf></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="1.5"/><rotate x="1" angle="180"/><translate z="4.5"/></transform>
    <emitter type="area"><rgb name="radiance" value="6, 5, 3.5"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><translate z="4.3"/></transform>
    <bsdf type="dielectric"><string name="cauchy" value="1.5, 0.04"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="180"/><translate z="4.2"/></transform>
    <bsdf type="dielectric"><string name="cauchy" value="1.5, 0.04"/></bsdf></shape>)";
    // A pane of the same glass (two parallel interfaces 0.1 apart) between the camera and the
    // scene: every camera subpath is dispersed too, and every connection of bdpt joins two
    // hero-only subpaths, where the factor 4 of terminate_secondary() must count once.
    if (behind_glass)
        text += R"(
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="90"/><translate y="-3.2" z="1.2"/></transform>
    <bsdf type="dielectric"><string name="cauchy" value="1.5, 0.04"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/><translate y="-3.1" z="1.2"/></transform>
    <bsdf type="dielectric"><string name="cauchy" value="1.5, 0.04"/></bsdf></shape>)";
    for (size_t at; (at = text.find("SIZE")) != std::string::npos;) text.replace(at, 4, std::to_string(size));
    return text + "\n</scene>";
}

}  // namespace pathlab::test
