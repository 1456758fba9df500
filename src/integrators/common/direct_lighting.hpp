// Direct lighting at a shading point, shared by every estimator: next-event estimation (light
// sampling), tracing a sampled direction to the emitter it finds, and the BSDF-sampled half of
// multiple importance sampling.
#pragma once

#include <optional>

#include "samplers/sampler.hpp"
#include "core/sampling.hpp"
#include "integrators/common/light_resampling.hpp"
#include "integrators/common/shading.hpp"
#include "integrators/common/transport.hpp"

namespace pathlab {

// One light chosen by the scene's light sampler (Scene::choose_light), one point or direction
// sampled on it (or, with ris, one of several such candidates: light_resampling.hpp), one shadow
// ray. Returns f * Le * cos(theta) / (pmf * pdfW) (ris: / NeeSample::pdf) in the path's colour (wl:
// transport.hpp). With `mis`, the result is weighted by the balance heuristic (the power heuristic
// with `power`) against BSDF sampling of the same direction (both densities in solid angle, the
// light's including its selection probability); delta lights cannot be found by BSDF sampling
// and keep weight 1.
// RIS's target at a surface (light_resampling.hpp): the luminance of the unshadowed
// contribution f * Le * |cos theta| of a candidate light sample; 0 behind an opaque surface.
inline float surface_target(const ShadingPoint& sp, const LightSample& c) {
    if (dot(c.wi, sp.ng) <= 0 && !sp.material->transmits()) return 0.0f;
    const Vec3f w = sp.frame.to_local(c.wi);
    float pdf;
    return luminance(sp.material->eval_and_pdf(sp, sp.wi, w, pdf)) * luminance(c.Le) * std::abs(w.z);
}

// The candidates next-event estimation draws at a surface (sp) or a point in a medium (null): a
// dispersive interface (which reduces wl to the hero) keeps the plain light sample, since its
// colour is known only per wavelength and RIS's target is in RGB.
template <class Wl>
int nee_candidates(const Scene& scene, const ShadingPoint* sp, const Wl& wl) {
    return sp && changes_wavelengths(*sp->material, wl) ? 1 : scene.light_sampler().candidates();
}

// The density of the other strategy of MIS for a direction wo (local) whose BSDF density is
// pdf_bsdf: BSDF sampling's own (a guided path tracer passes its mixture's).
struct BsdfStrategyPdf {
    float operator()(const Vec3f&, float pdf_bsdf) const { return pdf_bsdf; }
};

// A guided path tracer's distribution of directions at a vertex (ppg): the continuation is drawn
// from the one-sample mixture a p_scatter + (1 - a) p_guide (a Dirac lobe only from the BSDF
// half, with probability a times its own), and light sampling is weighed against the mixture's
// density. NoGuide, everyone else's: the BSDF or phase function alone (a = 1).
//   bool guides() const;              whether the vertex is guided (else a = 1)
//   float fraction() const;           a
//   float pdf(const Vec3f& w) const;  p_guide of a world direction, per steradian
//   Vec3f sample(Vec2f u) const;      a world direction drawn from p_guide
//   float mixture(const Vec3f& w, float pdf_scatter) const;  the continuation's density of w
//   float mis_pdf(const Vec3f& w, float pdf_scatter) const;  the density light sampling is weighed against
struct NoGuide {
    bool guides() const { return false; }
    float fraction() const { return 1.0f; }
    float pdf(const Vec3f&) const { return 0.0f; }
    Vec3f sample(Vec2f) const { return Vec3f(0.0f, 0.0f, 1.0f); }
    float mixture(const Vec3f&, float pdf_scatter) const { return pdf_scatter; }
    float mis_pdf(const Vec3f&, float pdf_scatter) const { return pdf_scatter; }
};

// A continuation at a surface drawn from the BSDF, or (from_guide) from the guide with the BSDF
// evaluated there: the sample, its value f, its world direction and the continuation's density
// (guide.mixture; a Dirac lobe's a times its own). None where the BSDF has no sample, or is black
// in the guide's direction.
template <class Wl>
struct GuidedBsdfSample {
    BsdfSample s;
    ColourAt<Wl> f;
    Vec3f wo_world;
    float pdf;
};

template <class Wl, class Guide>
std::optional<GuidedBsdfSample<Wl>> sample_bsdf_or_guide(const ShadingPoint& sp, Vec2f u, bool from_guide, const Guide& guide, Wl& wl) {
    std::optional<BsdfSample> s;
    ColourAt<Wl> f(0.0f);
    if (!from_guide) {
        s = bsdf_sample(sp, u, wl);
        if (!s) return std::nullopt;
        f = bsdf_sample_colour(sp, *s, wl);
    } else {
        const Vec3f wo = sp.frame.to_local(guide.sample(u));
        float pdf_bsdf = 0;
        f = bsdf_eval(sp, wo, wl, pdf_bsdf);
        if (is_black(f)) return std::nullopt;
        s = BsdfSample{wo, Rgb(0.0f), pdf_bsdf, false, 0, 0};
    }
    const Vec3f wo_world = sp.frame.to_world(s->wo);
    const float pdf = s->delta ? guide.fraction() * s->pdfW : guide.mixture(wo_world, s->pdfW);
    return GuidedBsdfSample<Wl>{*s, f, wo_world, pdf};
}

// The light a light sample found, for estimators that learn from it (a guided path tracer): its
// direction and the radiance arriving from it over the sample's density, MIS-weighted.
template <class Wl>
struct LightSampleSeen {
    bool found = false;
    Vec3f wi;
    ColourAt<Wl> Li{0.0f};
};

template <class Wl, class OtherPdf = BsdfStrategyPdf>
ColourAt<Wl> estimate_light_sample(const Scene& scene, const ShadingPoint& sp, Sampler& sampler, bool mis, Wl& wl, bool power = false,
                                   const OtherPdf& other_pdf = {}, LightSampleSeen<Wl>* seen = nullptr, bool split = true) {
    using Colour = ColourAt<Wl>;
    const bool dispersive = changes_wavelengths(*sp.material, wl);
    const bool transmits = sp.material->transmits();
    Colour sum(0.0f);
    float seen_y = -1;  // with splitting, `seen` gets the brightest of the samples
    const auto one = [&](const NeeSample& nee) -> Colour {
        const LightSample* ls = &nee.ls;
        // Lights behind the surface reach it only through a transmitting material (rough glass, a
        // thin sheet).
        if (dot(ls->wi, sp.ng) <= 0 && !transmits) return Colour(0.0f);
        const Vec3f wo = sp.frame.to_local(ls->wi);
        // The BSDF in RGB first (a shadow ray is traced only where it is not black), its colour once
        // the light is known to be visible; a dispersive interface at once.
        float pdf_bsdf;
        Colour f(0.0f);
        Rgb f_rgb(0.0f);
        if (dispersive) [[unlikely]] {
            f = bsdf_eval(sp, wo, wl, pdf_bsdf);
            if (is_black(f)) return Colour(0.0f);
        } else {
            f_rgb = sp.material->eval_and_pdf(sp, sp.wi, wo, pdf_bsdf);
            if (is_black(f_rgb)) return Colour(0.0f);
        }
        const Ray shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi)
                                                    : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
        if (scene.occluded(shadow)) return Colour(0.0f);
        if (!dispersive) f = bsdf_colour(sp, wo, f_rgb, wl);
        const float weight = (mis && !ls->delta) ? mis_heuristic(power, nee.pdf_source, other_pdf(wo, pdf_bsdf)) : 1.0f;
        const ColourAt<Wl> Le = light_colour(scene, nee.choice.index, ls->Le, wl);
        if (seen) {
            const ColourAt<Wl> Li = Le * (weight / nee.pdf);
            const float y = max_component(f * Li);
            if (y > seen_y) *seen = {true, ls->wi, Li}, seen_y = y;
        }
        return f * Le * (std::abs(wo.z) * weight / nee.pdf);
    };
    for_each_nee_sample(scene, sp.p, sp.frame.n, sampler, nee_candidates(scene, &sp, wl),
                        [&](const LightSample& c, int) { return surface_target(sp, c); },
                        [&](const NeeSample& nee) { sum += one(nee); }, split);
    return sum;
}

// The direct estimators' first hit: `L` becomes what the camera ray sees there (the emitter it
// hits or the sky; nothing with `hide`), and the shading point is returned unless the ray escaped
// or the surface is black.
template <class Wl>
std::optional<ShadingPoint> first_surface(const Scene& scene, const Ray& ray, bool hide, const Wl& wl, ColourAt<Wl>& L) {
    Intersection hit;
    if (!scene.intersect(ray, hit)) {
        L = hide ? ColourAt<Wl>(0.0f) : escaped_radiance(scene, ray.d, wl);
        return std::nullopt;
    }
    L = hide ? ColourAt<Wl>(0.0f) : emitted_radiance(scene, hit, -ray.d, wl);
    const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
    if (sp.material->is_black()) return std::nullopt;
    return sp;
}

// What a ray leaving a shading point finds: the surface it hits (if any), the radiance emitted
// towards the shading point (a front-facing area light, or the environment if the ray
// escapes), and the solid-angle density with which light sampling at `from` (a surface with
// normal n) would have produced this direction, including the light's selection probability (of
// a splitting choice with `split`: for_each_nee_sample). The BSDF-sampled half of MIS weighs its
// emission with this density.
struct EmitterHit {
    bool hit = false;
    Intersection isect;
    Rgb Le{0.0f};
    float pdf_light = 0;
};

inline EmitterHit trace_to_emitter(const Scene& scene, const Ray& ray, const Vec3f& from, const Vec3f& n, bool split = true) {
    EmitterHit e;
    e.hit = scene.intersect(ray, e.isect);
    if (!e.hit) {
        const int env = scene.environment_light();
        if (env >= 0) {
            e.Le = scene.escaped_radiance(ray.d);
            e.pdf_light = scene.light_pmf(from, n, env, split) * environment_pdf_li(scene.lights()[size_t(env)], ray.d);
        }
        return e;
    }
    e.Le = emitted_radiance(scene, e.isect, -ray.d / length(ray.d));
    if (!is_black(e.Le)) {
        const Light& light = scene.lights()[size_t(e.isect.light)];
        e.pdf_light = scene.light_pmf(from, n, e.isect.light, split) * surface_light_pdf_li(light, from, e.isect.p, e.isect.ng);
    }
    return e;
}

// The BSDF-sampled half of MIS direct lighting: traces the sampled direction and returns the
// emission it finds weighted by the balance heuristic (the power heuristic with `power`) against
// light sampling (weight 1 for a delta BSDF sample, which light sampling cannot produce); `f` is
// the sample's colour (bsdf_sample_colour). `found` receives the hit, for path tracers that
// continue from it.
template <class Wl>
ColourAt<Wl> estimate_bsdf_sample_mis(const Scene& scene, const ShadingPoint& sp, const BsdfSample& s, const ColourAt<Wl>& f,
                                      EmitterHit& found, const Wl& wl, bool power = false, bool split = true) {
    found = trace_to_emitter(scene, sp.spawn(s.wo), sp.p, sp.frame.n, split);
    if (is_black(found.Le)) return ColourAt<Wl>(0.0f);
    const float weight = s.delta ? 1.0f : mis_heuristic(power, s.pdfW, found.pdf_light);
    const int light = found.hit ? found.isect.light : scene.environment_light();
    return f * light_colour(scene, light, found.Le, wl) * (std::abs(s.wo.z) * weight / s.pdfW);
}

}  // namespace pathlab
