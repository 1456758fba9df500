// Direct light where a path scatters in a scene with media (a surface, or a point in a medium),
// as volpath gathers it at every vertex and the photon methods (sppm, ppm, pm) at their visible
// points: a light sample whose shadow ray carries its transmittance, and a BSDF or phase sample
// whose walk through the media may reach an emitter, combined by the balance heuristic (the
// power heuristic with `power`, volpath's --mis power). The
// sample's walk is also the path's continuation (volpath goes on along it).
#pragma once

#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/media_walk.hpp"

namespace pathlab {

// A point where the path scatters: a surface (sp) or a point in a medium (phase).
struct ScatterVertex {
    const ShadingPoint* sp = nullptr;
    const MediumWalk* hit = nullptr;  // the walk that ended on the surface (its geometric normal, its shape's media)
    Vec3f p;
    Vec3f wi;  // medium vertices: unit world direction back along the path
    const PhaseFunction* phase = nullptr;
    int32_t medium = -1;  // the medium the path arrived in
};

// What the path replay (src/diff/path_replay.cpp) asks of estimate_light: nothing, for the
// renderers. A hook's begin() starts each light sample, piece(medium, length) follows its shadow
// ray through the media, and sample(nee, f, Le, k, Tr, contribution) ends one that contributes
// (contribution = f Le k Tr, k = cos * MIS weight / density).
struct NoLightHook {
    static constexpr bool kActive = false;
    void begin() const {}
    void piece(int32_t, float) const {}
    template <class... A> void sample(const A&...) const {}
};

// Next-event estimation at a vertex: pt-mis's estimate_light_sample (the same random numbers,
// the same arithmetic at a surface), with the shadow ray's transmittance. With `seen`, the light
// it found (its direction, and Le Tr times the MIS weight over the sample's density).
template <class T, class Guide = NoGuide, class Hook = NoLightHook>
ColourOf<T> estimate_light(const Scene& scene, const ScatterVertex& v, Sampler& sampler, MediumState<T>& st, bool mis,
                           WavelengthsOf<T>& wl, bool power = false, const Guide& guide = {}, LightSampleSeen<WavelengthsOf<T>>* seen = nullptr,
                           bool split = true, Hook&& hook = {}) {
    using Colour = ColourOf<T>;
    Colour sum(0.0f);
    float seen_y = -1;  // with splitting, `seen` gets the brightest of the samples
    const auto one = [&](const NeeSample& nee) -> Colour {
        hook.begin();
        const LightChoice choice = nee.choice;
        const LightSample* ls = &nee.ls;
        Colour f;
        float pdf_scatter, cosine;
        Ray shadow;
        int32_t medium = v.medium;
        if (v.sp) {
            const ShadingPoint& sp = *v.sp;
            if (dot(ls->wi, sp.ng) <= 0 && !sp.material->transmits()) return Colour(0.0f);
            const Vec3f wo = sp.frame.to_local(ls->wi);
            f = bsdf_eval(sp, wo, wl, pdf_scatter);
            if (is_black(f)) return Colour(0.0f);
            cosine = std::abs(wo.z);
            shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi) : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
            medium = medium_after(v.hit->media, v.hit->isect.ng, ls->wi, medium);
        } else {
            const float p = phase_eval(*v.phase, v.wi, ls->wi);
            if (!(p > 0)) return Colour(0.0f);
            f = Colour(p);
            pdf_scatter = phase_pdf(*v.phase, v.wi, ls->wi);
            cosine = 1;
            if (std::isinf(ls->distance)) {
                shadow = Ray{v.p, ls->wi, kInf};
            } else {
                const Vec3f to = is_black(ls->normal) ? ls->point
                                                      : offset_ray_origin(ls->point, dot(ls->point - v.p, ls->normal) <= 0 ? ls->normal : -ls->normal);
                shadow = Ray{v.p, to - v.p, 1.0f - 1e-4f};
            }
        }
        if (!st.pass_null && scene.media_separated(medium, scene.light_medium(choice.index))) return Colour(0.0f);  // blocked: no ray needed
        Colour Tr;
        if constexpr (std::decay_t<Hook>::kActive)
            Tr = shadow_transmittance(scene, shadow, medium, st, nullptr, [&](int32_t m, float length) { hook.piece(m, length); });
        else
            Tr = shadow_transmittance(scene, shadow, medium, st);
        if (is_black(Tr)) return Colour(0.0f);
        const float weight = !ls->delta ? (mis ? mis_heuristic(power, nee.pdf_source, guide.mis_pdf(ls->wi, pdf_scatter)) : 1.0f) : 1.0f;
        const Colour contribution = f * light_colour(scene, choice.index, ls->Le, wl) * (cosine * weight / nee.pdf);
        const bool attenuated = scene.has_media() || st.pass_null;
        if (seen) {
            const Colour Li = light_colour(scene, choice.index, ls->Le, wl) * (attenuated ? Tr : Colour(1.0f)) * (weight / nee.pdf);
            const float y = max_component(f * Li);
            if (y > seen_y) *seen = {true, ls->wi, Li}, seen_y = y;
        }
        if constexpr (std::decay_t<Hook>::kActive)
            hook.sample(nee, f, light_colour(scene, choice.index, ls->Le, wl), cosine * weight / nee.pdf, attenuated ? Tr : Colour(1.0f),
                        attenuated ? contribution * Tr : contribution);
        return attenuated ? contribution * Tr : contribution;
    };
    for_each_nee_sample(scene, v.p, v.sp ? v.sp->frame.n : Vec3f(0.0f), sampler, nee_candidates(scene, v.sp, wl),
                        [&](const LightSample& c, int) {
                            return v.sp ? surface_target(*v.sp, c) : phase_eval(*v.phase, v.wi, c.wi) * luminance(c.Le);
                        },
                        [&](const NeeSample& nee) { sum += one(nee); }, split);
    return sum;
}

// The radiance a walk that ended on a surface or in the sky finds (Le towards the path, in RGB),
// the density with which light sampling at `from` would have chosen it (trace_to_emitter's), and
// the light it belongs to.
inline EmitterHit emission_found(const Scene& scene, const MediumWalk& w, const Vec3f& from, const Vec3f& n, int& light, bool split = true) {
    EmitterHit e;
    light = -1;
    if (w.kind == MediumWalk::kEscaped) {
        const int env = scene.environment_light();
        if (env >= 0) {
            light = env;
            e.Le = scene.escaped_radiance(w.dir);
            e.pdf_light = scene.light_pmf(from, n, env, split) * environment_pdf_li(scene.lights()[size_t(env)], w.dir);
        }
    } else if (w.kind == MediumWalk::kSurface) {
        e.Le = emitted_radiance(scene, w.isect, -w.dir / length(w.dir));
        if (!is_black(e.Le)) {
            light = w.isect.light;
            const Light& l = scene.lights()[size_t(w.isect.light)];
            e.pdf_light = scene.light_pmf(from, n, w.isect.light, split) * surface_light_pdf_li(l, from, w.isect.p, w.isect.ng);
        }
    }
    return e;
}

// Where the path last scattered, for the MIS weight of emission found past surfaces it passed
// straight through (--null-depth skip): those are no vertices, so light sampling from here,
// whose shadow rays pass them too, is the sample's partner. The camera: a delta, weight 1.
struct MisOrigin {
    Vec3f p{}, n{};  // n: the shading normal at a surface, 0 in a medium
    float pdf = 0;   // the solid-angle density of the direction sampled there
    bool delta = true;
    bool split = true;  // whether light sampling split there (for_each_nee_sample)
};

// A BSDF or phase sample at a vertex and the walk along it.
template <class T>
struct ScatterSample {
    bool sampled = false;             // false: no sample (the path ends, nothing found)
    Ray ray{};                        // the sampled ray
    int32_t medium = -1;              // the medium it starts in
    MediumWalk next;                  // the walk along the sampled direction
    ColourOf<T> next_seg{1.0f};       // its free-flight weights
    ColourOf<T> weight{0.0f};         // f cos / pdf of the sampled direction
    ColourOf<T> found{0.0f};          // the emission the walk reached, times f cos / pdf and the MIS weight against light sampling
    uint32_t lobe = 0;                // the BSDF lobe sampled (BsdfLobe; 0 for a phase sample)
    float pdf = 0;                    // the solid-angle density of the sampled direction
    float pdf_scatter = 0;            // ... the BSDF's or phase function's own (pdf without a guide)
    bool delta = false;               // ... a Dirac delta's coefficient
    // For the path replay: the BSDF's or phase function's value, a surface sample's local
    // direction, and the light the walk found (-1: none) with its Le and k (found = f Le k).
    ColourOf<T> f{0.0f};
    Vec3f wo_local{};
    int light = -1;
    ColourOf<T> Le{0.0f};
    float k = 0;
};

// The second half of the MIS pair at v (the first is estimate_light): a BSDF sample at a surface
// (whose vertex and walk are v.sp and v.hit) or a phase sample in a medium, and the emission its
// walk finds; the caller adds beta * next_seg * found / density. With `null_origin`, emission
// found by a straight pass (kLobeNull) is weighed against light sampling at that origin. Where
// `guide` guides, the direction comes from its mixture (NoGuide: the BSDF's or phase function's
// sample alone); its random numbers are u, then the choice of half, then the half's own.
// Each piece of the walk in a medium goes to on_piece, as walk_media says.
template <class T, class Guide = NoGuide, class OnPiece = NoPieces>
ScatterSample<T> sample_scatter(const Scene& scene, const ScatterVertex& v, Sampler& sampler, MediumState<T>& st, bool mis,
                                WavelengthsOf<T>& wl, bool power = false, const MisOrigin* null_origin = nullptr, const Guide& guide = {},
                                bool split = true, OnPiece&& on_piece = {}) {
    using Colour = ColourOf<T>;
    ScatterSample<T> n;
    int light;
    const Vec2f u = sampler.next2d();
    const bool guided = guide.guides() && !(sampler.next1d() < guide.fraction());  // (NoGuide draws no choice)
    if (v.sp) {
        const ShadingPoint& sp = *v.sp;
        const MediumWalk& w = *v.hit;
        const auto g = sample_bsdf_or_guide(sp, u, guided, guide, wl);
        if (!g) return n;
        const BsdfSample* s = &g->s;
        const Colour& f = g->f;
        const Vec3f& wo_world = g->wo_world;
        n.sampled = true;
        n.lobe = s->lobe;
        n.pdf_scatter = s->pdfW;
        n.pdf = g->pdf;
        if (guide.guides() && !(n.pdf > 0)) return ScatterSample<T>{};
        n.delta = s->delta;
        n.ray = sp.spawn(s->wo);
        n.medium = medium_after(w.media, w.isect.ng, wo_world, w.medium);
        n.next = walk_media(scene, n.ray, n.medium, st, n.next_seg, nullptr, on_piece);
        n.weight = f * (std::abs(s->wo.z) / n.pdf);
        n.f = f;
        n.wo_local = s->wo;
        const bool passed = null_origin && (s->lobe & kLobeNull);
        const MisOrigin here{sp.p, sp.frame.n, n.pdf, s->delta, split};
        const MisOrigin& o = passed ? *null_origin : here;
        const EmitterHit e = emission_found(scene, n.next, o.p, o.n, light, o.split);
        const float weight = o.delta ? 1.0f : (mis ? mis_heuristic(power, o.pdf, e.pdf_light) : 0.0f);
        if (!is_black(e.Le)) {
            n.Le = light_colour(scene, light, e.Le, wl);
            n.k = std::abs(s->wo.z) * weight / n.pdf;
            n.found = f * n.Le * n.k;
            n.light = light;
        }
    } else {
        PhaseSample ps;
        if (!guided) {
            ps = phase_sample(*v.phase, v.wi, u);
        } else {
            ps.wo = guide.sample(u);
            ps.p = phase_eval(*v.phase, v.wi, ps.wo);
            ps.pdfW = phase_pdf(*v.phase, v.wi, ps.wo);
        }
        if (!(ps.pdfW > 0)) return n;
        n.sampled = true;
        n.pdf_scatter = ps.pdfW;
        n.pdf = guide.mixture(ps.wo, ps.pdfW);
        n.ray = Ray{v.p, ps.wo, kInf};
        n.medium = v.medium;
        n.next = walk_media(scene, n.ray, n.medium, st, n.next_seg, nullptr, on_piece);
        const EmitterHit e = emission_found(scene, n.next, v.p, Vec3f(0.0f), light, split);
        const float weight = mis ? mis_heuristic(power, n.pdf, e.pdf_light) : 0.0f;
        n.f = Colour(ps.p);
        if (!is_black(e.Le)) {
            n.Le = light_colour(scene, light, e.Le, wl);
            n.k = weight / n.pdf;
            n.found = n.f * n.Le * n.k;
            n.light = light;
        }
        n.weight = Colour(ps.p / n.pdf);
    }
    return n;
}

}  // namespace pathlab
