// The camera side of the photon methods (sppm, ppm, pm): a camera ray followed through Dirac lobes
// (mirrors, glass, plastic's coating) to its first other surface, the visible point, where the
// photons are gathered. Emission found on the way is added to L: there it is seen directly or
// through Dirac lobes only, and no other strategy has it.
#pragma once

#include <optional>

#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/media_lighting.hpp"
#include "media/free_flight.hpp"

namespace pathlab {

template <class T>
struct VisiblePoint {
    ShadingPoint sp;
    ColourOf<T> beta;  // the camera path's throughput up to it
    int t;             // its index on the camera path (z_1 first): t - 1 bounces before it
};

// `counts(length)`: whether paths of that many bounces count (all, or one length only).
// No visible point: the path escaped, met a black surface, a failed sample, or ran past
// max_bounces or max_dirac Dirac vertices. `wl`: the path's wavelengths (a dispersive interface
// reduces them to the hero).
template <class T, typename Counts>
std::optional<VisiblePoint<T>> trace_to_visible_point(const Scene& scene, Ray ray, Sampler& sampler, int max_bounces, int max_dirac,
                                                      const Counts& counts, ColourOf<T>& L, WavelengthsOf<T>& wl) {
    ColourOf<T> beta(1.0f);
    for (int t = 1; t - 1 <= max_bounces && t <= max_dirac; ++t) {
        Intersection hit;
        if (!scene.intersect(ray, hit)) {
            if (counts(t - 1)) L += beta * escaped_radiance(scene, ray.d, wl);
            return std::nullopt;
        }
        const Vec3f d = normalize(ray.d);
        if (counts(t - 1)) L += beta * emitted_radiance(scene, hit, -d, wl);
        const ShadingPoint sp = make_shading_point(scene, hit, d);
        if (sp.material->is_black() || t > max_bounces) return std::nullopt;
        if (!sp.material->is_delta()) return VisiblePoint<T>{sp, beta, t};
        const auto s = bsdf_sample(sp, sampler.next2d(), wl);
        if (!s) return std::nullopt;
        beta *= bsdf_sample_colour(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        ray = sp.spawn(s->wo);
    }
    return std::nullopt;
}

// The same through participating media (sppm, ppm and pm in a scene with media): the walk crosses
// media and index-matched boundaries as well as Dirac lobes. Without beams the media are walked
// by distance sampling (delta tracking, as volpath: the throughput takes the free-flight weights,
// st.r the channels' distance densities) and the visible point may be a scattering point in a
// medium; with beams the walk never scatters in a medium: for each piece of ray through one it
// adds beta * beam(o, d, tmax, medium, Tr, phase, t) to L (d unit, Tr the transmittance along the
// piece, t the index the piece's points take on the camera path), and goes on with the piece's
// transmittance.
template <class T>
struct MediumVisiblePoint {
    MediumWalk w;       // the walk that ended at it: its surface and that surface's media, or its point in a medium
    ShadingPoint sp;    // on a surface
    ColourOf<T> beta;   // the camera path's throughput up to it
    int t;              // its index on the camera path

    bool in_medium() const { return w.kind == MediumWalk::kMedium; }
    // The vertex as direct lighting sees it (it points into this visible point).
    ScatterVertex vertex(const Scene& scene) const {
        ScatterVertex v;
        v.medium = w.medium;
        if (in_medium()) {
            v.p = w.p;
            v.wi = -w.dir / length(w.dir);
            v.phase = &medium_phase(scene.medium(w.medium));
        } else {
            v.sp = &sp, v.hit = &w, v.p = sp.p;
        }
        return v;
    }
};

struct MediaWalkRules {
    int first_t = 1;      // the index on the camera path of the walk's first vertex
    int max_bounces = 0;  // bounces of the whole camera path
    int max_dirac = 0;    // Dirac vertices followed in a row before giving up
    bool beams = false;
    bool emission = true;  // add the emission found on the way (a gathering ray's is another strategy's)
};

template <class T, typename Counts, typename Beam>
std::optional<MediumVisiblePoint<T>> trace_to_visible_point_in_media(const Scene& scene, Ray ray, int32_t medium, ColourOf<T> beta,
                                                                     Sampler& sampler, MediumState<T>& st, const MediaWalkRules& rules,
                                                                     const Counts& counts, const Beam& beam, ColourOf<T>& L,
                                                                     WavelengthsOf<T>& wl) {
    using Colour = ColourOf<T>;
    thread_local TransmittanceTrack<Colour> track;
    for (int t = rules.first_t; t - 1 <= rules.max_bounces && t - rules.first_t < rules.max_dirac; ++t) {
        MediumWalk w;
        if (!rules.beams) {
            Colour seg(1.0f);
            w = walk_media(scene, ray, medium, st, seg);
            beta *= seg;
        } else {
            for (int crossings = 0;; ++crossings) {
                w = MediumWalk{};
                w.dir = ray.d;
                w.medium = medium;
                const bool hit = crossings < kMaxCrossings && intersect_with_boundaries(scene, ray, w.isect, w.media);
                if (medium >= 0 && has_extinction(scene.medium(medium))) {
                    const float len = length(ray.d);
                    const Vec3f d = ray.d / len;
                    const float tmax = hit ? w.isect.t * len : kInf;
                    track_transmittance(medium_view(scene.medium(medium), wl), ray.o, d, tmax, st.rng(), track);
                    L += beta * beam(ray.o, d, tmax, medium, track, medium_phase(scene.medium(medium)), t);
                    beta *= track.at(tmax);
                    if (is_black(beta)) return std::nullopt;
                }
                if (!hit) {
                    w.kind = crossings < kMaxCrossings ? MediumWalk::kEscaped : MediumWalk::kLost;
                    break;
                }
                if (!(w.media && w.media->index_matched)) {
                    w.kind = MediumWalk::kSurface;
                    break;
                }
                medium = medium_after(w.media, w.isect.ng, ray.d, medium);
                ray = spawn_ray(w.isect.p, w.isect.ng, ray.d);
            }
        }
        if (w.kind == MediumWalk::kLost) return std::nullopt;
        if (w.kind == MediumWalk::kEscaped) {
            if (rules.emission && counts(t - 1)) L += beta * escaped_radiance(scene, w.dir, wl) / st.density();
            return std::nullopt;
        }
        if (w.kind == MediumWalk::kMedium) {
            if (t > rules.max_bounces) return std::nullopt;
            return MediumVisiblePoint<T>{w, ShadingPoint{}, beta, t};
        }
        if (rules.emission && counts(t - 1)) L += beta * emitted_radiance(scene, w.isect, -w.dir / length(w.dir), wl) / st.density();
        ShadingPoint sp = make_shading_point(scene, w.isect, w.dir);
        if (sp.material->is_black() || t > rules.max_bounces) return std::nullopt;
        if (!sp.material->is_delta()) return MediumVisiblePoint<T>{w, sp, beta, t};
        const auto s = bsdf_sample(sp, sampler.next2d(), wl);
        if (!s) return std::nullopt;
        beta *= bsdf_sample_colour(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
        medium = medium_after(w.media, w.isect.ng, sp.frame.to_world(s->wo), w.medium);
        ray = sp.spawn(s->wo);
    }
    return std::nullopt;
}

}  // namespace pathlab
