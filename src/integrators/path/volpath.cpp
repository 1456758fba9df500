// volpath: volumetric path tracing. pt-mis's loop (its MIS pair of a light sample and a
// BSDF sample at every surface, the BSDF sample continuing the path) with participating media:
//  - every ray walks through media and index-matched boundaries (walk()): in a medium it may
//    scatter, sampled by delta tracking (free-flight sampling, media/medium.hpp), and a
//    boundary only changes the medium; it ends at a scattering point, a surface or the sky;
//  - at a scattering point the phase function plays the BSDF's part: a light sample and a
//    phase sample, combined by the balance heuristic, the phase sample continuing the path;
//  - a light sample's shadow ray crosses boundaries and media too, and its contribution is
//    multiplied by their transmittance (closed form, or ratio tracking in grids), estimated
//    with the random numbers of a second stream;
//  - RGB: a hero channel chosen per path drives distance sampling, with spectral MIS over the
//    three channels (beta / mean(r), media/medium.hpp); Russian roulette on that ratio.
// Media's random numbers (the hero channel, distances, ratio tracking) come from a fork of the
// sample's stream (Sampler::fork), so a path that meets no medium draws exactly pt-mis's
// numbers in pt-mis's order and does pt-mis's arithmetic: in a scene without media volpath's
// image is pt-mis's, bit for bit (tests/test_volumes.cpp).
#include "integrators/path/volpath.hpp"

#include <optional>

#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/path/pt_mis.hpp"
#include "integrators/path/volpath_spectral.hpp"

namespace pathlab {
namespace {

constexpr uint64_t kMediumStream = 0x766f6c70617468ull;  // "volpath"
// A ray crossing more index-matched boundaries than this without an event is stuck (numerically).
constexpr int kMaxCrossings = 256;

// The random numbers of media along one path, and its spectral MIS state.
struct MediumState {
    const Sampler& parent;
    std::optional<Sampler> stream{};  // forked on first use
    int hero = -1;
    Rgb r{1.0f};  // the three channels' path densities over a common normaliser

    Sampler& rng() {
        if (!stream) stream.emplace(parent.fork(kMediumStream));
        return *stream;
    }
    int hero_channel() {
        if (hero < 0) hero = std::min(2, int(rng().next1d() * 3));
        return hero;
    }
};

// Where a walk along a ray ended.
struct Walk {
    enum Kind { kSurface, kMedium, kEscaped, kLost } kind = kEscaped;
    Intersection isect{};  // kSurface
    const MediumInterface* media = nullptr;  // kSurface: its shape's media (null: it changes none)
    Vec3f p{};             // kMedium: the scattering point
    Vec3f dir{};           // the direction of the last ray, as it was given (not normalised)
    int32_t medium = -1;  // the medium the walk ended in
};

// The medium on the far side of a surface (geometric normal ng, its shape's media) for a ray
// leaving it in direction w.
int32_t medium_after(const MediumInterface* media, const Vec3f& ng, const Vec3f& w, int32_t current) {
    return media && media->changes_medium() ? media->medium_towards(w, ng) : current;
}

// Scene::intersect with every shape of a scene with media (index-matched boundaries included),
// or as pt-mis does in a scene without.
bool intersect(const Scene& scene, const Ray& ray, Intersection& hit, const MediumInterface*& media) {
    media = nullptr;
    return scene.has_media() ? scene.intersect(ray, hit, kMaskAll, media) : scene.intersect(ray, hit);
}

// Follows `ray` from medium `medium` through media and index-matched boundaries. `seg` is
// multiplied by the free-flight weights (and st.r by the channels' densities).
Walk walk(const Scene& scene, Ray ray, int32_t medium, MediumState& st, Rgb& seg) {
    for (int crossings = 0; crossings < kMaxCrossings; ++crossings) {
        Walk w;
        w.dir = ray.d;
        w.medium = medium;
        const bool hit = intersect(scene, ray, w.isect, w.media);
        if (medium >= 0) {
            const float len = length(ray.d);
            const Vec3f d = ray.d / len;
            const FreeFlight ff = sample_free_flight(scene.medium(medium), ray.o, d, hit ? w.isect.t * len : kInf,
                                                     st.hero_channel(), st.rng(), seg, st.r);
            if (ff.scattered) {
                w.kind = Walk::kMedium;
                w.p = ray.o + d * ff.t;
                return w;
            }
            if (is_black(seg)) return {Walk::kLost};
        }
        if (!hit) return w;  // kEscaped
        if (!(w.media && w.media->index_matched)) {
            w.kind = Walk::kSurface;
            return w;
        }
        medium = medium_after(w.media, w.isect.ng, ray.d, medium);
        ray = spawn_ray(w.isect.p, w.isect.ng, ray.d);
    }
    return {Walk::kLost};
}

// The transmittance along a shadow ray (a segment ending a little before its target, or a ray
// to infinity) starting in `medium`: 0 if a surface blocks it, else the product of the media's
// transmittance estimates between the index-matched boundaries it crosses.
Rgb transmittance(const Scene& scene, Ray shadow, int32_t medium, MediumState& st) {
    if (!scene.has_media()) return scene.occluded(shadow) ? Rgb(0.0f) : Rgb(1.0f);
    const bool segment = std::isfinite(shadow.tmax);
    const Vec3f target = shadow.o + shadow.d;  // (segments: d = target - origin)
    Rgb T(1.0f);
    for (int crossings = 0; crossings < kMaxCrossings; ++crossings) {
        Intersection isect;
        const MediumInterface* media = nullptr;
        const bool hit = scene.intersect(shadow, isect, kMaskAll, media);
        if (hit && !(media && media->index_matched)) return Rgb(0.0f);
        if (medium >= 0) {
            const float len = length(shadow.d);
            const float t = hit ? isect.t : shadow.tmax;
            T *= estimate_transmittance(scene.medium(medium), shadow.o, shadow.d / len, segment || hit ? t * len : kInf, st.rng());
            if (is_black(T)) return T;
        }
        if (!hit) return T;
        medium = medium_after(media, isect.ng, shadow.d, medium);
        if (segment) {
            const Vec3f from = offset_ray_origin(isect.p, dot(shadow.d, isect.ng) >= 0 ? isect.ng : -isect.ng);
            shadow = Ray{from, target - from, shadow.tmax};
        } else {
            shadow = spawn_ray(isect.p, isect.ng, shadow.d);
        }
    }
    return Rgb(0.0f);
}

// A point where the path scatters: a surface (sp) or a point in a medium (phase).
struct Vertex {
    const ShadingPoint* sp = nullptr;
    const Walk* hit = nullptr;  // the walk that ended on the surface (its geometric normal, its shape's media)
    Vec3f p;
    Vec3f wi;  // medium vertices: unit world direction back along the path
    const PhaseFunction* phase = nullptr;
    int32_t medium = -1;  // the medium the path arrived in
};

// Next-event estimation at a vertex: pt-mis's estimate_light_sample (the same random numbers,
// the same arithmetic at a surface), with the shadow ray's transmittance.
Rgb estimate_light(const Scene& scene, const Vertex& v, Sampler& sampler, MediumState& st, bool mis) {
    const LightChoice choice = scene.choose_light(sampler.next1d());
    const Vec2f u = sampler.next2d();
    if (choice.index < 0) return Rgb(0.0f);
    const auto ls = sample_light(scene.lights()[size_t(choice.index)], v.p, u);
    if (!ls || is_black(ls->Le)) return Rgb(0.0f);
    Rgb f;
    float pdf_scatter, cosine;
    Ray shadow;
    int32_t medium = v.medium;
    if (v.sp) {
        const ShadingPoint& sp = *v.sp;
        if (dot(ls->wi, sp.ng) <= 0 && !sp.material->is_dielectric()) return Rgb(0.0f);
        const Vec3f wo = sp.frame.to_local(ls->wi);
        f = sp.material->eval_and_pdf(sp, sp.wi, wo, pdf_scatter);
        if (is_black(f)) return Rgb(0.0f);
        cosine = std::abs(wo.z);
        shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi) : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
        medium = medium_after(v.hit->media, v.hit->isect.ng, ls->wi, medium);
    } else {
        const float p = phase_eval(*v.phase, v.wi, ls->wi);
        if (!(p > 0)) return Rgb(0.0f);
        f = Rgb(p);
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
    const Rgb T = transmittance(scene, shadow, medium, st);
    if (is_black(T)) return Rgb(0.0f);
    const float pdf_light = choice.pmf * ls->pdfW;
    const float weight = !ls->delta ? (mis ? balance_heuristic(pdf_light, pdf_scatter) : 1.0f) : 1.0f;
    const Rgb contribution = f * ls->Le * (cosine * weight / pdf_light);
    return scene.has_media() ? contribution * T : contribution;
}

// The radiance a walk that ended on a surface or in the sky finds (Le towards the path), and
// the density with which light sampling at `from` would have chosen it (trace_to_emitter's).
EmitterHit emission_found(const Scene& scene, const Walk& w, const Vec3f& from) {
    EmitterHit e;
    if (w.kind == Walk::kEscaped) {
        const int env = scene.environment_light();
        if (env >= 0) {
            e.Le = scene.escaped_radiance(w.dir);
            e.pdf_light = scene.light_pmf(env) * environment_pdf_li(scene.lights()[size_t(env)], w.dir);
        }
    } else if (w.kind == Walk::kSurface) {
        e.Le = emitted_radiance(scene, w.isect, -w.dir / length(w.dir));
        if (!is_black(e.Le)) {
            const Light& light = scene.lights()[size_t(w.isect.light)];
            e.pdf_light = scene.light_pmf(w.isect.light) * surface_light_pdf_li(light, from, w.isect.p, w.isect.ng);
        }
    }
    return e;
}

class Volpath final : public PixelIntegrator {
public:
    Volpath(const IntegratorOptions& o, VolpathSettings s)
        : rules_(o), mis_(s.mis), pt_mis_without_media_(s.pt_mis_without_media), hide_(o.hide_emitters) {}

    Rgb radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler) const override {
        if (!scene.has_media() && pt_mis_without_media_) {  // pt-mis's own loop: the same image, pt-mis's speed
            Intersection hit;
            if (!scene.intersect(camera_ray, hit)) return hide_ ? Rgb(0.0f) : scene.escaped_radiance(camera_ray.d);
            const Rgb emitted = hide_ ? Rgb(0.0f) : emitted_radiance(scene, hit, -camera_ray.d);
            return pt_mis_from_hit(scene, hit, camera_ray.d, 0, sampler, rules_, false, -1, emitted);
        }
        MediumState st{sampler};
        Rgb seg(1.0f);
        Walk w = walk(scene, camera_ray, scene.camera_medium(), st, seg);
        Rgb beta = seg;
        // What the camera sees directly (pt-mis: L starts as the emission at the first hit).
        Rgb L(0.0f);
        // (hide_emitters: not the emitters and the sky seen directly, also through media.)
        if (w.kind == Walk::kEscaped) return hide_ ? Rgb(0.0f) : beta * scene.escaped_radiance(w.dir) / mean(st.r);
        if (w.kind == Walk::kSurface && !hide_) L = beta * emitted_radiance(scene, w.isect, -w.dir) / mean(st.r);
        for (int bounces = 0; w.kind != Walk::kLost && rules_.may_bounce(bounces); ++bounces) {
            Vertex v;
            v.medium = w.medium;
            ShadingPoint sp;
            if (w.kind == Walk::kSurface) {
                sp = make_shading_point(scene, w.isect, w.dir);
                if (sp.material->is_black()) break;
                v.sp = &sp;
                v.hit = &w;
                v.p = sp.p;
            } else {
                v.p = w.p;
                v.wi = -w.dir / length(w.dir);
                v.phase = &medium_phase(scene.medium(w.medium));
            }
            // The MIS pair: a light sample, and a BSDF or phase sample whose walk may find emission.
            const Rgb direct = estimate_light(scene, v, sampler, st, mis_);
            L += beta * direct / mean(st.r);

            Rgb weight_next;  // f cos / pdf of the continuation
            Walk next;
            Rgb next_seg(1.0f);  // its walk's free-flight weights
            if (v.sp) {
                const auto s = sp.material->sample(sp, sp.wi, sampler.next2d());
                if (!s) {
                    break;  // pt-mis: no BSDF sample, nothing found, and the path ends
                }
                next = walk(scene, sp.spawn(s->wo), medium_after(w.media, w.isect.ng, sp.frame.to_world(s->wo), w.medium), st,
                            next_seg);
                weight_next = s->f * (std::abs(s->wo.z) / s->pdfW);
                const EmitterHit e = emission_found(scene, next, sp.p);
                const float weight = s->delta ? 1.0f : (mis_ ? balance_heuristic(s->pdfW, e.pdf_light) : 0.0f);
                const Rgb found = is_black(e.Le) ? Rgb(0.0f) : s->f * e.Le * (std::abs(s->wo.z) * weight / s->pdfW);
                L += beta * next_seg * found / mean(st.r);
            } else {
                const PhaseSample ps = phase_sample(*v.phase, v.wi, sampler.next2d());
                if (!(ps.pdfW > 0)) break;
                next = walk(scene, Ray{v.p, ps.wo, kInf}, w.medium, st, next_seg);
                const EmitterHit e = emission_found(scene, next, v.p);
                const float weight = mis_ ? balance_heuristic(ps.pdfW, e.pdf_light) : 0.0f;
                const Rgb found = is_black(e.Le) ? Rgb(0.0f) : Rgb(ps.p) * e.Le * (weight / ps.pdfW);
                L += beta * next_seg * found / mean(st.r);
                weight_next = Rgb(ps.p / ps.pdfW);
            }
            if (!rules_.may_bounce(bounces + 1)) break;
            if (next.kind == Walk::kEscaped || next.kind == Walk::kLost) break;
            beta = beta * next_seg * weight_next;
            if (!survive_roulette(bounces + 1, beta, st.r, sampler)) break;
            w = next;
        }
        return L;
    }

    // Spectral mode: volpath_spectral.cpp's copy of the loop above.
    Spectrum4 radiance_spectral(const Scene& scene, const Ray& camera_ray, Sampler& sampler, SampledWavelengths& wl) const override {
        return volpath_spectral_radiance(scene, camera_ray, sampler, wl, rules_, {mis_, pt_mis_without_media_, hide_});
    }

private:
    // Russian roulette on beta / mean(r), the path's actual weight (pt-mis's exactly when r = 1).
    bool survive_roulette(int bounces, Rgb& beta, const Rgb& r, Sampler& sampler) const {
        const float m = mean(r);
        if (m == 1) return rules_.survive_roulette(bounces, beta, sampler);
        Rgb weight = beta / m;
        if (!rules_.survive_roulette(bounces, weight, sampler)) return false;
        beta = weight * m;
        return true;
    }

    PathRules rules_;
    bool mis_, pt_mis_without_media_, hide_;
};

}  // namespace

std::unique_ptr<Integrator> make_volpath(const IntegratorOptions& options, VolpathSettings settings) {
    return std::make_unique<Volpath>(options, settings);
}

const IntegratorInfo& volpath_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"volpath", {"volpathmis"}, "volumetric path tracing: participating media, delta tracking, MIS",
                         false, true, path_params(), [](const IntegratorOptions& o) { return make_volpath(o); }};
        i.spectral = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
