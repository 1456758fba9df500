// volpath in spectral mode: volpath.cpp's walk, shadow-ray transmittance, light sample and loop,
// line for line, with Spectrum4 values at the path's wavelengths (docs/spectral.md). What differs
// from RGB mode:
//  - the hero is lane 0 (no hero channel is drawn: the 4 wavelengths are exchangeable, see
//    spectral_media.hpp), so the media stream's first number is a distance, not a channel;
//  - the path density is spectral_path_density(r, wl): mean(r) over the 4 lanes, or r_0 once a
//    dispersive interface has left the hero alone;
//  - values (BSDF, phase: grey, emission, media) at the wavelengths; sampling is RGB mode's.
// In a scene without media a path draws pt-mis's numbers and does pt_mis_spectral_from_hit's
// arithmetic (r stays 1, and x / 1 = x), so its image is spectral pt-mis's bit for bit
// (tests/test_spectral_volpath.cpp), as volpath's is pt-mis's in RGB mode.
#include "integrators/path/volpath_spectral.hpp"

#include <optional>

#include "integrators/common/spectral_direct_lighting.hpp"
#include "integrators/common/spectral_media.hpp"
#include "integrators/path/pt_mis_spectral.hpp"

namespace pathlab {
namespace {

constexpr uint64_t kMediumStream = 0x766f6c70617468ull;  // volpath.cpp's "volpath" stream
constexpr int kMaxCrossings = 256;                        // as volpath.cpp

// The random numbers of media along one path, and its spectral MIS state (hero lane 0).
struct MediumState {
    const Sampler& parent;
    const SampledWavelengths& wl;
    float majorant_factor = 1;
    std::optional<Sampler> stream{};
    Spectrum4 r{1.0f};  // the 4 lanes' path densities over a common normaliser

    Sampler& rng() {
        if (!stream) stream.emplace(parent.fork(kMediumStream));
        return *stream;
    }
    float density() const { return spectral_path_density(r, wl); }
};

struct Walk {
    enum Kind { kSurface, kMedium, kEscaped, kLost } kind = kEscaped;
    Intersection isect{};
    const MediumInterface* media = nullptr;
    Vec3f p{};
    Vec3f dir{};
    int32_t medium = -1;
};

int32_t medium_after(const MediumInterface* media, const Vec3f& ng, const Vec3f& w, int32_t current) {
    return media && media->changes_medium() ? media->medium_towards(w, ng) : current;
}

bool intersect(const Scene& scene, const Ray& ray, Intersection& hit, const MediumInterface*& media) {
    media = nullptr;
    return scene.has_media() ? scene.intersect(ray, hit, kMaskAll, media) : scene.intersect(ray, hit);
}

Walk walk(const Scene& scene, Ray ray, int32_t medium, MediumState& st, Spectrum4& seg) {
    for (int crossings = 0; crossings < kMaxCrossings; ++crossings) {
        Walk w;
        w.dir = ray.d;
        w.medium = medium;
        const bool hit = intersect(scene, ray, w.isect, w.media);
        if (medium >= 0) {
            const float len = length(ray.d);
            const Vec3f d = ray.d / len;
            const FreeFlight ff = sample_free_flight_spectral(scene.medium(medium), ray.o, d, hit ? w.isect.t * len : kInf, st.rng(), seg,
                                                              st.r, st.wl, st.majorant_factor);
            if (ff.scattered) {
                w.kind = Walk::kMedium;
                w.p = ray.o + d * ff.t;
                return w;
            }
            if (seg.is_black()) return {Walk::kLost};
        }
        if (!hit) return w;
        if (!(w.media && w.media->index_matched)) {
            w.kind = Walk::kSurface;
            return w;
        }
        medium = medium_after(w.media, w.isect.ng, ray.d, medium);
        ray = spawn_ray(w.isect.p, w.isect.ng, ray.d);
    }
    return {Walk::kLost};
}

Spectrum4 transmittance(const Scene& scene, Ray shadow, int32_t medium, MediumState& st) {
    if (!scene.has_media()) return scene.occluded(shadow) ? Spectrum4(0.0f) : Spectrum4(1.0f);
    const bool segment = std::isfinite(shadow.tmax);
    const Vec3f target = shadow.o + shadow.d;
    Spectrum4 T(1.0f);
    for (int crossings = 0; crossings < kMaxCrossings; ++crossings) {
        Intersection isect;
        const MediumInterface* media = nullptr;
        const bool hit = scene.intersect(shadow, isect, kMaskAll, media);
        if (hit && !(media && media->index_matched)) return Spectrum4(0.0f);
        if (medium >= 0) {
            const float len = length(shadow.d);
            const float t = hit ? isect.t : shadow.tmax;
            T *= estimate_transmittance_spectral(scene.medium(medium), shadow.o, shadow.d / len, segment || hit ? t * len : kInf, st.rng(),
                                                 st.wl, st.majorant_factor);
            if (T.is_black()) return T;
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
    return Spectrum4(0.0f);
}

struct Vertex {
    const ShadingPoint* sp = nullptr;
    const Walk* hit = nullptr;
    Vec3f p;
    Vec3f wi;
    const PhaseFunction* phase = nullptr;
    int32_t medium = -1;
};

// volpath.cpp's estimate_light at the wavelengths (the same random numbers and rays).
Spectrum4 estimate_light(const Scene& scene, const Vertex& v, Sampler& sampler, MediumState& st, bool mis, SampledWavelengths& wl) {
    const LightChoice choice = scene.choose_light(sampler.next1d());
    const Vec2f u = sampler.next2d();
    if (choice.index < 0) return Spectrum4(0.0f);
    const auto ls = sample_light(scene.lights()[size_t(choice.index)], v.p, u);
    if (!ls || is_black(ls->Le)) return Spectrum4(0.0f);
    Spectrum4 f;
    float pdf_scatter, cosine;
    Ray shadow;
    int32_t medium = v.medium;
    if (v.sp) {
        const ShadingPoint& sp = *v.sp;
        if (dot(ls->wi, sp.ng) <= 0 && !sp.material->is_dielectric()) return Spectrum4(0.0f);
        const Vec3f wo = sp.frame.to_local(ls->wi);
        f = spectral_eval_and_pdf(sp, wo, wl, pdf_scatter);
        if (f.is_black()) return Spectrum4(0.0f);
        cosine = std::abs(wo.z);
        shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi) : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
        medium = medium_after(v.hit->media, v.hit->isect.ng, ls->wi, medium);
    } else {
        const float p = phase_eval(*v.phase, v.wi, ls->wi);
        if (!(p > 0)) return Spectrum4(0.0f);
        f = Spectrum4(p);
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
    const Spectrum4 T = transmittance(scene, shadow, medium, st);
    if (T.is_black()) return Spectrum4(0.0f);
    const float pdf_light = choice.pmf * ls->pdfW;
    const float weight = !ls->delta ? (mis ? balance_heuristic(pdf_light, pdf_scatter) : 1.0f) : 1.0f;
    const Spectrum4 contribution = f * emission_spectrum(scene, choice.index, ls->Le, wl) * (cosine * weight / pdf_light);
    return scene.has_media() ? contribution * T : contribution;
}

// volpath.cpp's emission_found: the RGB radiance a walk found and light sampling's density,
// with the index of the light it belongs to (for emission_spectrum).
EmitterHit emission_found(const Scene& scene, const Walk& w, const Vec3f& from, int& light) {
    EmitterHit e;
    light = -1;
    if (w.kind == Walk::kEscaped) {
        const int env = scene.environment_light();
        if (env >= 0) {
            light = env;
            e.Le = scene.escaped_radiance(w.dir);
            e.pdf_light = scene.light_pmf(env) * environment_pdf_li(scene.lights()[size_t(env)], w.dir);
        }
    } else if (w.kind == Walk::kSurface) {
        e.Le = emitted_radiance(scene, w.isect, -w.dir / length(w.dir));
        if (!is_black(e.Le)) {
            light = w.isect.light;
            const Light& l = scene.lights()[size_t(w.isect.light)];
            e.pdf_light = scene.light_pmf(w.isect.light) * surface_light_pdf_li(l, from, w.isect.p, w.isect.ng);
        }
    }
    return e;
}

// Russian roulette on beta / density, the path's actual weight (volpath.cpp's).
bool survive_roulette(const PathRules& rules, int bounces, Spectrum4& beta, float density, Sampler& sampler) {
    if (density == 1) return rules.survive_roulette(bounces, beta, sampler);
    Spectrum4 weight = beta / density;
    if (!rules.survive_roulette(bounces, weight, sampler)) return false;
    beta = weight * density;
    return true;
}

}  // namespace

Spectrum4 volpath_spectral_radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, SampledWavelengths& wl,
                                    const PathRules& rules, const VolpathSpectralSettings& settings) {
    const bool hide = settings.hide_emitters, mis = settings.mis;
    if (!scene.has_media() && settings.pt_mis_without_media) {
        Intersection hit;
        if (!scene.intersect(camera_ray, hit)) return hide ? Spectrum4(0.0f) : escaped_spectrum(scene, camera_ray.d, wl);
        const Spectrum4 emitted = hide ? Spectrum4(0.0f) : emitted_spectrum(scene, hit, -camera_ray.d, wl);
        return pt_mis_spectral_from_hit(scene, hit, camera_ray.d, 0, sampler, rules, false, -1, emitted, wl);
    }
    MediumState st{sampler, wl, settings.majorant_factor};
    Spectrum4 seg(1.0f);
    Walk w = walk(scene, camera_ray, scene.camera_medium(), st, seg);
    Spectrum4 beta = seg;
    Spectrum4 L(0.0f);
    if (w.kind == Walk::kEscaped) return hide ? Spectrum4(0.0f) : beta * escaped_spectrum(scene, w.dir, wl) / st.density();
    if (w.kind == Walk::kSurface && !hide) L = beta * emitted_spectrum(scene, w.isect, -w.dir, wl) / st.density();
    for (int bounces = 0; w.kind != Walk::kLost && rules.may_bounce(bounces); ++bounces) {
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
        const Spectrum4 direct = estimate_light(scene, v, sampler, st, mis, wl);
        L += beta * direct / st.density();

        Spectrum4 weight_next;
        Walk next;
        Spectrum4 next_seg(1.0f);
        if (v.sp) {
            const auto s = spectral_sample(sp, sampler.next2d(), wl);
            if (!s) break;
            next = walk(scene, sp.spawn(s->wo), medium_after(w.media, w.isect.ng, sp.frame.to_world(s->wo), w.medium), st, next_seg);
            const Spectrum4 f = spectral_sample_value(sp, *s, wl);
            weight_next = f * (std::abs(s->wo.z) / s->pdfW);
            int light;
            const EmitterHit e = emission_found(scene, next, sp.p, light);
            const float weight = s->delta ? 1.0f : (mis ? balance_heuristic(s->pdfW, e.pdf_light) : 0.0f);
            const Spectrum4 found =
                is_black(e.Le) ? Spectrum4(0.0f) : f * emission_spectrum(scene, light, e.Le, wl) * (std::abs(s->wo.z) * weight / s->pdfW);
            L += beta * next_seg * found / st.density();
        } else {
            const PhaseSample ps = phase_sample(*v.phase, v.wi, sampler.next2d());
            if (!(ps.pdfW > 0)) break;
            next = walk(scene, Ray{v.p, ps.wo, kInf}, w.medium, st, next_seg);
            int light;
            const EmitterHit e = emission_found(scene, next, v.p, light);
            const float weight = mis ? balance_heuristic(ps.pdfW, e.pdf_light) : 0.0f;
            const Spectrum4 found =
                is_black(e.Le) ? Spectrum4(0.0f) : Spectrum4(ps.p) * emission_spectrum(scene, light, e.Le, wl) * (weight / ps.pdfW);
            L += beta * next_seg * found / st.density();
            weight_next = Spectrum4(ps.p / ps.pdfW);
        }
        if (!rules.may_bounce(bounces + 1)) break;
        if (next.kind == Walk::kEscaped || next.kind == Walk::kLost) break;
        beta = beta * next_seg * weight_next;
        if (!survive_roulette(rules, bounces + 1, beta, st.density(), sampler)) break;
        w = next;
    }
    return L;
}

}  // namespace pathlab
