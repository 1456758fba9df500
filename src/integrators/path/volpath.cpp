// volpath: volumetric path tracing. pt-mis's loop (its MIS pair of a light sample and a
// BSDF sample at every surface, the BSDF sample continuing the path) with participating media:
//  - every ray walks through media and index-matched boundaries (walk_media(), common/media_walk.hpp): in a medium it may
//    scatter, sampled by delta tracking (free-flight sampling, media/medium.hpp), and a
//    boundary only changes the medium; it ends at a scattering point, a surface or the sky;
//  - at a scattering point the phase function plays the BSDF's part: a light sample and a
//    phase sample, combined by the balance heuristic, the phase sample continuing the path;
//  - a light sample's shadow ray crosses boundaries and media too, and its contribution is
//    multiplied by their transmittance (closed form, or ratio tracking in grids), estimated
//    with the random numbers of a second stream;
//  - a hero channel drives distance sampling, with spectral MIS over the channels (beta /
//    path_density(r), media/medium.hpp): in RGB one of the three chosen per path, in spectral
//    mode the hero wavelength (media/spectral_medium.hpp); Russian roulette on that ratio.
// Media's random numbers (the hero channel, distances, ratio tracking) come from a fork of the
// sample's stream (Sampler::fork), so a path that meets no medium draws exactly pt-mis's
// numbers in pt-mis's order and does pt-mis's arithmetic: in a scene without media volpath's
// image is pt-mis's, bit for bit (tests/test_volumes.cpp), in RGB and in spectral mode.
#include "integrators/path/volpath.hpp"

#include <optional>

#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/media_walk.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/path/pt_mis.hpp"

namespace pathlab {
namespace {

// A point where the path scatters: a surface (sp) or a point in a medium (phase).
struct Vertex {
    const ShadingPoint* sp = nullptr;
    const MediumWalk* hit = nullptr;  // the walk that ended on the surface (its geometric normal, its shape's media)
    Vec3f p;
    Vec3f wi;  // medium vertices: unit world direction back along the path
    const PhaseFunction* phase = nullptr;
    int32_t medium = -1;  // the medium the path arrived in
};

// Next-event estimation at a vertex: pt-mis's estimate_light_sample (the same random numbers,
// the same arithmetic at a surface), with the shadow ray's transmittance.
template <class T>
ColourOf<T> estimate_light(const Scene& scene, const Vertex& v, Sampler& sampler, MediumState<T>& st, bool mis, WavelengthsOf<T>& wl) {
    using Colour = ColourOf<T>;
    const LightChoice choice = scene.choose_light(sampler.next1d());
    const Vec2f u = sampler.next2d();
    if (choice.index < 0) return Colour(0.0f);
    const auto ls = sample_light(scene.lights()[size_t(choice.index)], v.p, u);
    if (!ls || is_black(ls->Le)) return Colour(0.0f);
    Colour f;
    float pdf_scatter, cosine;
    Ray shadow;
    int32_t medium = v.medium;
    if (v.sp) {
        const ShadingPoint& sp = *v.sp;
        if (dot(ls->wi, sp.ng) <= 0 && !sp.material->is_dielectric()) return Colour(0.0f);
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
    const Colour Tr = shadow_transmittance(scene, shadow, medium, st);
    if (is_black(Tr)) return Colour(0.0f);
    const float pdf_light = choice.pmf * ls->pdfW;
    const float weight = !ls->delta ? (mis ? balance_heuristic(pdf_light, pdf_scatter) : 1.0f) : 1.0f;
    const Colour contribution = f * light_colour(scene, choice.index, ls->Le, wl) * (cosine * weight / pdf_light);
    return scene.has_media() ? contribution * Tr : contribution;
}

// The radiance a walk that ended on a surface or in the sky finds (Le towards the path, in RGB),
// the density with which light sampling at `from` would have chosen it (trace_to_emitter's), and
// the light it belongs to.
EmitterHit emission_found(const Scene& scene, const MediumWalk& w, const Vec3f& from, int& light) {
    EmitterHit e;
    light = -1;
    if (w.kind == MediumWalk::kEscaped) {
        const int env = scene.environment_light();
        if (env >= 0) {
            light = env;
            e.Le = scene.escaped_radiance(w.dir);
            e.pdf_light = scene.light_pmf(env) * environment_pdf_li(scene.lights()[size_t(env)], w.dir);
        }
    } else if (w.kind == MediumWalk::kSurface) {
        e.Le = emitted_radiance(scene, w.isect, -w.dir / length(w.dir));
        if (!is_black(e.Le)) {
            light = w.isect.light;
            const Light& l = scene.lights()[size_t(w.isect.light)];
            e.pdf_light = scene.light_pmf(w.isect.light) * surface_light_pdf_li(l, from, w.isect.p, w.isect.ng);
        }
    }
    return e;
}

template <class T>
class Volpath final : public PixelIntegrator<T> {
public:
    using Colour = ColourOf<T>;

    Volpath(const IntegratorOptions& o, VolpathSettings s) : rules_(o), settings_(s), hide_(o.hide_emitters) {}

    Colour radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, WavelengthsOf<T>& wl) const override {
        if (!scene.has_media() && settings_.pt_mis_without_media) {  // pt-mis's own loop: the same image, pt-mis's speed
            Intersection hit;
            if (!scene.intersect(camera_ray, hit)) return hide_ ? Colour(0.0f) : escaped_radiance(scene, camera_ray.d, wl);
            const Colour emitted = hide_ ? Colour(0.0f) : emitted_radiance(scene, hit, -camera_ray.d, wl);
            return pt_mis_from_hit(scene, hit, camera_ray.d, 0, sampler, rules_, wl, false, -1, emitted);
        }
        const bool mis = settings_.mis;
        MediumState<T> st{sampler, wl, settings_.majorant_factor};
        Colour seg(1.0f);
        MediumWalk w = walk_media(scene, camera_ray, scene.camera_medium(), st, seg);
        Colour beta = seg;
        // What the camera sees directly (pt-mis: L starts as the emission at the first hit).
        Colour L(0.0f);
        // (hide_emitters: not the emitters and the sky seen directly, also through media.)
        if (w.kind == MediumWalk::kEscaped) return hide_ ? Colour(0.0f) : beta * escaped_radiance(scene, w.dir, wl) / st.density();
        if (w.kind == MediumWalk::kSurface && !hide_) L = beta * emitted_radiance(scene, w.isect, -w.dir, wl) / st.density();
        for (int bounces = 0; w.kind != MediumWalk::kLost && rules_.may_bounce(bounces); ++bounces) {
            Vertex v;
            v.medium = w.medium;
            ShadingPoint sp;
            if (w.kind == MediumWalk::kSurface) {
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
            const Colour direct = estimate_light(scene, v, sampler, st, mis, wl);
            L += beta * direct / st.density();

            Colour weight_next;  // f cos / pdf of the continuation
            MediumWalk next;
            Colour next_seg(1.0f);  // its walk's free-flight weights
            int light;
            if (v.sp) {
                const auto s = bsdf_sample(sp, sampler.next2d(), wl);
                if (!s) break;  // pt-mis: no BSDF sample, nothing found, and the path ends
                next = walk_media(scene, sp.spawn(s->wo), medium_after(w.media, w.isect.ng, sp.frame.to_world(s->wo), w.medium), st, next_seg);
                const Colour f = bsdf_sample_colour(sp, *s, wl);
                weight_next = f * (std::abs(s->wo.z) / s->pdfW);
                const EmitterHit e = emission_found(scene, next, sp.p, light);
                const float weight = s->delta ? 1.0f : (mis ? balance_heuristic(s->pdfW, e.pdf_light) : 0.0f);
                const Colour found =
                    is_black(e.Le) ? Colour(0.0f) : f * light_colour(scene, light, e.Le, wl) * (std::abs(s->wo.z) * weight / s->pdfW);
                L += beta * next_seg * found / st.density();
            } else {
                const PhaseSample ps = phase_sample(*v.phase, v.wi, sampler.next2d());
                if (!(ps.pdfW > 0)) break;
                next = walk_media(scene, Ray{v.p, ps.wo, kInf}, w.medium, st, next_seg);
                const EmitterHit e = emission_found(scene, next, v.p, light);
                const float weight = mis ? balance_heuristic(ps.pdfW, e.pdf_light) : 0.0f;
                const Colour found = is_black(e.Le) ? Colour(0.0f) : Colour(ps.p) * light_colour(scene, light, e.Le, wl) * (weight / ps.pdfW);
                L += beta * next_seg * found / st.density();
                weight_next = Colour(ps.p / ps.pdfW);
            }
            if (!rules_.may_bounce(bounces + 1)) break;
            if (next.kind == MediumWalk::kEscaped || next.kind == MediumWalk::kLost) break;
            beta = beta * next_seg * weight_next;
            if (!survive_roulette(bounces + 1, beta, st.density(), sampler)) break;
            w = next;
        }
        return L;
    }

private:
    // Russian roulette on beta / density, the path's actual weight (pt-mis's exactly when the density is 1).
    bool survive_roulette(int bounces, Colour& beta, float density, Sampler& sampler) const {
        if (density == 1) return rules_.survive_roulette(bounces, beta, sampler);
        Colour weight = beta / density;
        if (!rules_.survive_roulette(bounces, weight, sampler)) return false;
        beta = weight * density;
        return true;
    }

    PathRules rules_;
    VolpathSettings settings_;
    bool hide_;
};

}  // namespace

std::unique_ptr<Integrator> make_volpath(const IntegratorOptions& options, VolpathSettings settings) {
    return make_for_transport<Volpath>(options, settings);
}

const IntegratorInfo& volpath_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"volpath", {"volpathmis"}, "volumetric path tracing: participating media, delta tracking, MIS",
                         false, true, path_params(), [](const IntegratorOptions& o) { return make_volpath(o); }};
        i.media = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
