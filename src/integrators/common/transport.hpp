// How a path carries colour (docs/architecture.md, "How a path carries colour").
//
// Every integrator is written once, as a template over a Transport, and instantiated twice:
//   RgbTransport       a path carries an RGB triple (Rgb) and no wavelengths; every RGB input
//                      is used as it is (RGB mode, the default);
//   SpectralTransport  a path carries its values at 4 sampled wavelengths (Spectrum4 at a
//                      SampledWavelengths, hero wavelength sampling); RGB inputs are upsampled
//                      and emitters seen with their own spectra (spectral mode, --spectral;
//                      docs/spectral.md).
// The geometry of a path (its random numbers, directions, densities, lobe choices, MIS weights)
// is the same in both: sampling runs the RGB code of materials and lights, and only the colour of
// what was sampled is the transport's. So an integrator's body asks, with its path's wavelengths
// `wl` (an empty RgbWavelengths in RGB mode):
//   where a path starts     T::camera_wavelengths(sampler), or one set for a whole pass
//                           (T::pass_wavelengths: photons and the camera paths merging with them);
//   for an emitter          light_colour(scene, light, Le, wl), emitted_radiance(scene, hit, w, wl),
//                           escaped_radiance(scene, d, wl);
//   for a BSDF              bsdf_sample(sp, u, wl) (its direction), bsdf_sample_colour(sp, s, wl)
//                           (its value), bsdf_eval(sp, wo, wl, pdf), bsdf_colour(sp, wo, f_rgb, wl)
//                           (the value once its RGB evaluation said it is not black);
//   for other RGB inputs    reflectance_colour(rgb, wl), illuminant_colour(rgb, wl);
//   for a medium            the free flights and transmittances of media/free_flight.hpp through
//                           medium_view(medium, wl), hero_channel(...), path_density(r, wl);
//   where a sample ends     film_colour(L, wl): the linear sRGB the film accumulates.
// Every RGB function here is the identity on its RGB input (RGB mode's arithmetic is the one it
// always had); the spectral ones evaluate at the wavelengths. A dispersive interface (spectral
// only) leaves a path with the hero wavelength alone: wl.secondary_terminated() says so,
// hero_lane(c) drops the other lanes of a throughput, hero_only(L) expresses a hero-only
// contribution at the sample's 4 wavelengths (so that it can be summed with others).
#pragma once

#include <optional>

#include "bsdfs/spectral_bsdf.hpp"
#include "integrators/common/shading.hpp"
#include "media/spectral_medium.hpp"
#include "samplers/sampler.hpp"
#include "spectral/rgb_spectra.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab {

// RGB mode's wavelengths: none. A path never loses any.
struct RgbWavelengths {
    static constexpr bool secondary_terminated() { return false; }
    void terminate_secondary() {}
};

// The stream of a camera sample's wavelength number (Sampler::fork), apart from every stream
// RGB mode reads, so spectral mode leaves RGB mode's random numbers where they are; and the
// stream of a pass's wavelengths (one set for every path of a pass), no pixel's, light path's or
// filter shift's.
inline constexpr uint64_t kWavelengthStream = 0x5ec7a1e9f00d0001ull;
inline constexpr uint64_t kPassWavelengthStream = ~uint64_t(0) - 0x5ec7;

struct RgbTransport {
    static constexpr bool spectral = false;
    using Colour = Rgb;
    using Wavelengths = RgbWavelengths;
    // A camera sample's contributions to its own pixel, summed before the film sees them: in
    // double, as the film sums.
    using SampleSum = Vec3d;
    static Wavelengths camera_wavelengths(const Sampler&) { return {}; }
    static Wavelengths pass_wavelengths(uint64_t /*seed*/, SamplerKind, uint64_t /*pass*/) { return {}; }
};

struct SpectralTransport {
    static constexpr bool spectral = true;
    using Colour = Spectrum4;
    using Wavelengths = SampledWavelengths;
    // ... summed at the wavelengths and converted once (the film's estimator is linear).
    using SampleSum = Spectrum4;
    // A camera sample's wavelengths: a pure function of the sample's (seed, pixel, index).
    static Wavelengths camera_wavelengths(const Sampler& sampler) {
        return SampledWavelengths::sample_visible(sampler.fork(kWavelengthStream).next1d());
    }
    // The wavelengths every path of pass `pass` carries (with the Sobol sampler the passes' hero
    // wavelengths are stratified).
    static Wavelengths pass_wavelengths(uint64_t seed, SamplerKind kind, uint64_t pass) {
        Sampler sampler(seed, kPassWavelengthStream, pass, kind);
        return SampledWavelengths::sample_visible(sampler.next1d());
    }
};

template <class T> using ColourOf = typename T::Colour;
template <class T> using WavelengthsOf = typename T::Wavelengths;

// The transport of a path that carries wavelengths Wl, and its colour (for functions that take
// the path's wavelengths and return a colour: estimate_light_sample(..., wl)).
template <class Wl> struct TransportFor;
template <> struct TransportFor<RgbWavelengths> { using type = RgbTransport; };
template <> struct TransportFor<SampledWavelengths> { using type = SpectralTransport; };
template <class Wl> using ColourAt = ColourOf<typename TransportFor<Wl>::type>;

// ---- emitters ------------------------------------------------------------------------------
// `Le` is what light `light` (an index into scene.lights(), or -1) gave in RGB: a LightSample's
// or EmissionSample's Le, a surface emitter's radiance, the environment's. Every integrator
// turns emission into its colour through light_colour, so that emitters with a spectrum of their
// own (a black body) are seen with it in spectral mode.
inline Rgb light_colour(const Scene&, int /*light*/, const Rgb& Le, const RgbWavelengths&) { return Le; }
Spectrum4 light_colour(const Scene& scene, int light, const Rgb& Le, const SampledWavelengths& wl);

// The environment's radiance along an escaped ray's direction d (black without an environment).
inline Rgb escaped_radiance(const Scene& scene, const Vec3f& d, const RgbWavelengths&) { return scene.escaped_radiance(d); }
inline Spectrum4 escaped_radiance(const Scene& scene, const Vec3f& d, const SampledWavelengths& wl) {
    const int env = scene.environment_light();
    if (env < 0) return Spectrum4(0.0f);
    return light_colour(scene, env, scene.escaped_radiance(d), wl);
}

// The radiance a surface emitter at `hit` sends in direction w (black for other surfaces).
inline Rgb emitted_radiance(const Scene& scene, const Intersection& hit, const Vec3f& w, const RgbWavelengths&) {
    return emitted_radiance(scene, hit, w);
}
inline Spectrum4 emitted_radiance(const Scene& scene, const Intersection& hit, const Vec3f& w, const SampledWavelengths& wl) {
    const Rgb Le = emitted_radiance(scene, hit, w);
    if (is_black(Le)) return Spectrum4(0.0f);
    return light_colour(scene, hit.light, Le, wl);
}

// ---- BSDFs (bsdfs/spectral_bsdf.hpp) ---------------------------------------------------------
// The material's sample for the path: RGB mode's sample(); a dispersive interface refracts the
// hero wavelength and reduces wl to it.
inline std::optional<BsdfSample> bsdf_sample(const ShadingPoint& sp, const Vec2f& u, RgbWavelengths&) {
    return sp.material->sample(sp, sp.wi, u);
}
inline std::optional<BsdfSample> bsdf_sample(const ShadingPoint& sp, const Vec2f& u, SampledWavelengths& wl) {
    return spectral_sample(*sp.material, sp, sp.wi, u, wl);
}
// The value of a sample drawn by bsdf_sample (its coefficient s.f in RGB).
inline Rgb bsdf_sample_colour(const ShadingPoint&, const BsdfSample& s, const RgbWavelengths&) { return s.f; }
inline Spectrum4 bsdf_sample_colour(const ShadingPoint& sp, const BsdfSample& s, const SampledWavelengths& wl) {
    return spectral_sample_value(*sp.material, sp, sp.wi, s, wl);
}
// The BSDF for directions (sp.wi, wo) and its solid-angle density; a dispersive one reduces wl.
inline Rgb bsdf_eval(const ShadingPoint& sp, const Vec3f& wo, RgbWavelengths&, float& pdf) {
    return sp.material->eval_and_pdf(sp, sp.wi, wo, pdf);
}
inline Spectrum4 bsdf_eval(const ShadingPoint& sp, const Vec3f& wo, SampledWavelengths& wl, float& pdf) {
    return spectral_eval_and_pdf(*sp.material, sp, sp.wi, wo, wl, pdf);
}
// The same value without its density (RGB mode's eval()).
inline Rgb bsdf_eval(const ShadingPoint& sp, const Vec3f& wo, RgbWavelengths&) { return sp.material->eval(sp, sp.wi, wo); }
inline Spectrum4 bsdf_eval(const ShadingPoint& sp, const Vec3f& wo, SampledWavelengths& wl) {
    float pdf;
    if (is_dispersive(*sp.material)) [[unlikely]]
        return spectral_eval_and_pdf(*sp.material, sp, sp.wi, wo, wl, pdf);
    return spectral_eval(*sp.material, sp, sp.wi, wo, sp.material->eval(sp, sp.wi, wo), wl);
}
// The value for directions (sp.wi, wo) whose RGB value f_rgb is known (and not black): code
// that can decide from the RGB value (a shadow ray worth tracing) evaluates the colour after.
inline Rgb bsdf_colour(const ShadingPoint&, const Vec3f&, const Rgb& f_rgb, const RgbWavelengths&) { return f_rgb; }
inline Spectrum4 bsdf_colour(const ShadingPoint& sp, const Vec3f& wo, const Rgb& f_rgb, const SampledWavelengths& wl) {
    return spectral_eval(*sp.material, sp, sp.wi, wo, f_rgb, wl);
}
// Whether evaluating the material changes the wavelengths (a dispersive dielectric).
inline bool changes_wavelengths(const Material&, const RgbWavelengths&) { return false; }
inline bool changes_wavelengths(const Material& m, const SampledWavelengths&) { return is_dispersive(m); }

// ---- other RGB inputs ------------------------------------------------------------------------
inline Rgb reflectance_colour(const Rgb& rgb, const RgbWavelengths&) { return rgb; }
inline Spectrum4 reflectance_colour(const Rgb& rgb, const SampledWavelengths& wl) { return reflectance_spectrum(rgb, wl); }
// Light (an irradiance a cache holds in RGB), as an emitter's RGB radiance is seen.
inline Rgb illuminant_colour(const Rgb& rgb, const RgbWavelengths&) { return rgb; }
inline Spectrum4 illuminant_colour(const Rgb& rgb, const SampledWavelengths& wl) { return illuminant_spectrum(rgb, wl); }

// ---- media (media/free_flight.hpp) -----------------------------------------------------------
inline MediumRgb medium_view(const Medium& m, const RgbWavelengths&) { return {m}; }
inline MediumAtWavelengths medium_view(const Medium& m, const SampledWavelengths& wl) { return {m, wl}; }
// The channel whose coefficients drive free-flight sampling: in RGB one of the three, drawn
// uniformly (draw() gives a number in [0, 1)); spectrally the hero wavelength, lane 0 (nothing drawn).
template <class Draw> int hero_channel(const RgbWavelengths&, Draw&& draw) { return std::min(2, int(draw() * 3)); }
template <class Draw> int hero_channel(const SampledWavelengths&, Draw&&) { return 0; }
// A path's density over the common normaliser of the channels' techniques (medium.hpp): their
// mean, or the hero's alone once the path carries the hero alone.
// path_density_of: the same where the caller knows whether the path carries the hero alone (a
// path joined from two subpaths at the same wavelengths, bdpt: a vertex of either went through
// dispersion).
inline float path_density_of(const Rgb& r, bool) { return mean(r); }
inline float path_density_of(const Spectrum4& r, bool hero_only) { return hero_only ? r[0] : r.average(); }
inline float path_density(const Rgb& r, const RgbWavelengths&) { return mean(r); }
inline float path_density(const Spectrum4& r, const SampledWavelengths& wl) { return path_density_of(r, wl.secondary_terminated()); }

// a / b channel by channel, 0 where b is not positive (a throughput over a coefficient it includes).
inline Rgb divide_where_positive(Rgb a, const Rgb& b) {
    for (int c = 0; c < 3; ++c) a[c] = b[c] > 0 ? a[c] / b[c] : 0.0f;
    return a;
}
inline Spectrum4 divide_where_positive(Spectrum4 a, const Spectrum4& b) {
    for (int c = 0; c < kSpectrumLanes; ++c) a[c] = b[c] > 0 ? a[c] / b[c] : 0.0f;
    return a;
}

// ---- dispersion --------------------------------------------------------------------------------
// A throughput after a dispersive interface: the hero lane alone (the other lanes' light went
// elsewhere; their values must not keep a path alive in the roulette).
inline Rgb hero_lane(const Rgb& c) { return c; }
inline Spectrum4 hero_lane(const Spectrum4& c) { return Spectrum4(c[0], 0.0f, 0.0f, 0.0f); }
// A contribution whose path went through a dispersive interface, at the sample's 4 wavelengths:
// the film's estimator of (4 L_0, 0, 0, 0) with the 4 lanes' densities is that of L with the hero
// alone at density p(lambda_0) / 4 (sampled_wavelengths.hpp), so contributions of one sample with
// and without dispersion can be summed before the film's conversion.
inline Rgb hero_only(const Rgb& c) { return c; }
inline Spectrum4 hero_only(const Spectrum4& L) { return Spectrum4(4 * L[0], 0.0f, 0.0f, 0.0f); }

// ---- the film --------------------------------------------------------------------------------
// One sample's colour as the film accumulates it (linear sRGB): the film's XYZ estimator in
// spectral mode (xyz_estimator.hpp).
inline Vec3d film_colour(const Rgb& L, const RgbWavelengths&) { return Vec3d(L); }
inline Vec3d film_colour(const Vec3d& sum, const RgbWavelengths&) { return sum; }
inline Vec3d film_colour(const Spectrum4& L, const SampledWavelengths& wl) { return spectral_sample_to_linear_srgb(L, wl); }
// Adds a contribution to a sample's SampleSum (RgbTransport::SampleSum).
inline void accumulate(Vec3d& sum, const Rgb& c) { sum += Vec3d(c); }
inline void accumulate(Spectrum4& sum, const Spectrum4& c) { sum += c; }

}  // namespace pathlab
