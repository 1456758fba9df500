// The photon methods in spectral mode (pm, ppm, sppm; docs/spectral.md "Spectral photon mapping").
//
// A merge multiplies a camera path's throughput by a photon's power lane by lane, so both must
// carry the same wavelengths: every pass draws ONE SampledWavelengths from (seed, pass)
// (pass_wavelengths: a pure function of them, so passes stay independent of threads and of how
// they are split), and every camera path and every photon of that pass uses it. Each pass's
// per-pixel Spectrum4 is turned into linear sRGB by the film's estimator with the camera path's
// wavelengths before it reaches the film, as a spectral camera sample is.
//
// Photons keep RGB mode's `Photon` (position, direction, vertex: what the hashed grid and the
// k-d tree search) with its `power` unused, plus a parallel array of SpectralPower (the RGB
// types, their searches and RGB mode's hot loops are untouched).
//
// The light paths are bdpt's light subpaths (Bdpt::light_subpath, random_walk) traced again with
// the same random numbers in the same order, the same geometry (RGB sampling) and a Spectrum4
// throughput: emission through emission_spectrum, BSDF values through spectral_sample /
// spectral_sample_value in importance transport, Russian roulette on the largest lane.
//
// Dispersion: a photon path meeting a dispersive dielectric refracts the pass's hero wavelength
// and keeps only it (its copy of the wavelengths is terminated, its lanes 1-3 zeroed, the photon
// flagged hero_only). The factor 4 of terminate_secondary belongs once to the whole camera +
// light path: SpectralMergeSum counts a hero-only photon's lane 0 four times against a camera
// path that still has 4 lanes, once against a hero-only camera path (whose hero pdf is p/4
// already). spectral_sample samples a dispersive dielectric through Material::sample with the
// path's context at the hero's index, so importance transport's adjustments use that index.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "integrators/common/light_path_start.hpp"
#include "integrators/common/spectral_direct_lighting.hpp"
#include "integrators/integrator.hpp"
#include "integrators/photon/photon.hpp"

namespace pathlab {

// The wavelengths every path of pass `pass` carries: from a sampler stream no pixel, light path
// or filter shift uses, so with the Sobol sampler the passes' hero wavelengths are stratified.
inline constexpr uint64_t kPassWavelengthStream = ~uint64_t(0) - 0x5ec7;
inline SampledWavelengths pass_wavelengths(const RenderContext& ctx, uint64_t pass) {
    Sampler sampler(ctx.seed, kPassWavelengthStream, pass, ctx.sampler);
    return SampledWavelengths::sample_visible(sampler.next1d());
}

// A photon's spectral power (its light path's throughput, divided by the path count where the
// estimate wants it), parallel to a vector<Photon>: index i belongs to photon i.
struct SpectralPower {
    Spectrum4 power;
    bool hero_only = false;  // its path met a dispersive interface: lanes 1-3 are 0
};

// One vertex of a spectral light path where a photon may be stored: a non-Dirac surface.
struct SpectralPhotonVertex {
    Photon photon;          // p, wi (world, back towards where it came from), vertex index j; power unused
    Spectrum4 beta;         // the path's throughput arriving here
    bool hero_only;         // the path met a dispersive interface before
    bool through_dirac_only;  // y_1 .. y_{j-1} all scattered by Dirac lobes (pm's caustic map)
};

// bdpt's light subpath (Bdpt::light_subpath with max_vertices = its max_light_vertices()) with
// a spectral throughput at the wavelengths `wl`: calls visit(SpectralPhotonVertex) at every
// vertex y_j (j >= 1) on a non-Dirac surface, in path order. Returns nothing; the rays traced
// are counted by the scene.
template <typename Visit>
void trace_spectral_light_path(const Scene& scene, Sampler& sampler, SampledWavelengths wl, int max_vertices, int rr_depth,
                               Visit&& visit) {
    const auto start = start_light_path(scene, sampler);
    if (!start) return;
    const LightChoice& choice = start->choice;
    const EmissionSample* es = &start->emission;
    const uint32_t flags = start->flags;
    Spectrum4 beta = emission_spectrum(scene, choice.index, es->Le, wl) * (es->cos / (choice.pmf * es->pdfA * es->pdfW));
    Ray ray = (flags & kLightSurface) ? spawn_ray(es->origin, es->normal, es->direction) : Ray{es->origin, es->direction, kInf};
    Spectrum4 scatter(1.0f);  // the scattering's throughput alone, for Russian roulette
    bool through_dirac_only = true;
    for (int j = 1, bounces = 0;; ++j, ++bounces) {
        if (j >= max_vertices) return;
        Intersection hit;
        if (!scene.intersect(ray, hit)) return;
        const Vec3f d = normalize(ray.d);
        const ShadingPoint sp = make_shading_point(scene, hit, d, TransportMode::Importance);
        if (!sp.material->is_delta()) {
            const bool hero_only = wl.secondary_terminated();
            Spectrum4 b = beta;
            if (hero_only) b[1] = b[2] = b[3] = 0.0f;
            visit(SpectralPhotonVertex{Photon{hit.p, sp.frame.to_world(sp.wi), Rgb(0.0f), uint16_t(std::min(j, 65535))}, b, hero_only,
                                       through_dirac_only});
        }
        if (sp.material->is_black() || j + 1 >= max_vertices) return;
        const auto s = spectral_sample(sp, sampler.next2d(), wl);
        if (!s) return;
        const Spectrum4 weight = spectral_sample_value(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        beta *= weight;
        scatter *= weight;
        through_dirac_only &= s->delta;
        if (rr_depth >= 0 && bounces + 1 >= rr_depth) {
            const float q = std::clamp(scatter.max_value(), 0.05f, 1.0f);
            if (sampler.next1d() >= q) return;
            beta /= q;
            scatter /= q;
        }
        ray = sp.spawn(s->wo);
    }
}

// The camera side: trace_to_visible_point (visible_point.hpp) at the wavelengths wl (which a
// dispersive interface would reduce to the hero).
struct SpectralVisiblePoint {
    ShadingPoint sp;
    Spectrum4 beta;
    int t;
};

template <typename Counts>
std::optional<SpectralVisiblePoint> trace_to_visible_point_spectral(const Scene& scene, Ray ray, Sampler& sampler, int max_bounces,
                                                                    int max_dirac, const Counts& counts, Spectrum4& L,
                                                                    SampledWavelengths& wl) {
    Spectrum4 beta(1.0f);
    for (int t = 1; t - 1 <= max_bounces && t <= max_dirac; ++t) {
        Intersection hit;
        if (!scene.intersect(ray, hit)) {
            if (counts(t - 1)) L += beta * escaped_spectrum(scene, ray.d, wl);
            return std::nullopt;
        }
        const Vec3f d = normalize(ray.d);
        if (counts(t - 1)) L += beta * emitted_spectrum(scene, hit, -d, wl);
        const ShadingPoint sp = make_shading_point(scene, hit, d);
        if (sp.material->is_black() || t > max_bounces) return std::nullopt;
        if (!sp.material->is_delta()) return SpectralVisiblePoint{sp, beta, t};
        const auto s = spectral_sample(sp, sampler.next2d(), wl);
        if (!s) return std::nullopt;
        beta *= spectral_sample_value(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        ray = sp.spawn(s->wo);
    }
    return std::nullopt;
}

// The sums of f(x, wo, wi_p) power_p over the photons merged at one camera vertex, kept apart
// for photons of 4 lanes and hero-only ones, and their total by the rule of the factor 4
// (docs): a hero-only photon's lane 0 counts 4 times against a camera path of 4 lanes (the whole
// path is hero-only: its hero's pdf is p/4), once against a hero-only camera path (whose
// wavelengths carry that pdf already).
struct SpectralMergeSum {
    Spectrum4 full{0.0f}, hero{0.0f};
    void add(const Spectrum4& f, const SpectralPower& ph) {
        if (ph.hero_only) hero += f * ph.power;
        else full += f * ph.power;
    }
    Spectrum4 total(const SampledWavelengths& camera_wl) const {
        Spectrum4 h = hero;
        h[1] = h[2] = h[3] = 0.0f;
        return full + h * (camera_wl.secondary_terminated() ? 1.0f : 4.0f);
    }
};

// The BSDF value of a merge at sp for a photon arriving from world direction wi (black where RGB
// mode's eval is black).
inline Spectrum4 merge_bsdf_spectral(const ShadingPoint& sp, const Vec3f& wi_world, const SampledWavelengths& wl) {
    const Vec3f wo = sp.frame.to_local(wi_world);
    const Rgb f_rgb = sp.material->eval(sp, sp.wi, wo);
    return spectral_eval(sp, wo, f_rgb, wl);
}

}  // namespace pathlab
