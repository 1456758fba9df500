// Rays through participating media, as every integrator that renders media follows them
// (volpath, lt, bdpt): a walk from a ray's origin through media and index-matched boundaries to
// where it scatters (in a medium, sampled by delta tracking: media/free_flight.hpp), the surface
// it reaches, or the sky; and the transmittance along a shadow ray or a connection, 0 when a
// surface blocks it. A boundary that is no surface only changes the medium.
//
// Media's random numbers (the hero channel, distances, ratio tracking) come from a fork of the
// caller's sampler (Sampler::fork), so a path that meets no medium draws exactly the numbers it
// would draw in a scene without media (volpath is pt-mis bit for bit there).
//
// For the bidirectional methods' MIS weights the walk and the transmittance also multiply a
// deterministic scalar transmittance (mis_transmittance, media/medium.hpp) along the same pieces:
// the distance-sampling part of the densities, the same for every strategy of a path.
#pragma once

#include <optional>
#include <type_traits>

#include "integrators/common/shading.hpp"
#include "integrators/common/transport.hpp"

namespace pathlab {

constexpr uint64_t kMediumStream = 0x766f6c70617468ull;  // "volpath"
// A ray crossing more index-matched boundaries than this without an event is stuck (numerically).
constexpr int kMaxCrossings = 256;

// The random numbers of media along one path (or subpath), and its spectral MIS state.
template <class T>
struct MediumState {
    const Sampler& parent;
    const WavelengthsOf<T>& wl;
    float majorant_factor = 1;
    uint64_t stream_id = kMediumStream;  // the fork's
    std::optional<Sampler> stream{};  // forked on first use
    int hero = -1;  // drawn on first use unless set (the subpaths of one bdpt sample share it)
    ColourOf<T> r{1.0f};  // the channels' path densities over a common normaliser
    // --null-depth skip (volpath): shadow rays pass thin glass and masks' holes times their
    // null_transmission() instead of being blocked (the surfaces are no vertices of the path).
    bool pass_null = false;

    Sampler& rng() {
        if (!stream) stream.emplace(parent.fork(stream_id));
        return *stream;
    }
    int hero_channel() {
        if (hero < 0) hero = pathlab::hero_channel(wl, [this] { return rng().next1d(); });
        return hero;
    }
    float density() const { return path_density(r, wl); }
};

// Where a walk along a ray ended.
struct MediumWalk {
    enum Kind { kSurface, kMedium, kEscaped, kLost } kind = kEscaped;
    Intersection isect{};  // kSurface
    const MediumInterface* media = nullptr;  // kSurface: its shape's media (null: it changes none)
    Vec3f p{};             // kMedium: the scattering point
    Vec3f dir{};           // the direction of the last ray, as it was given (not normalised)
    int32_t medium = -1;  // the medium the walk ended in
};

// The medium on the far side of a surface (geometric normal ng, its shape's media) for a ray
// leaving it in direction w.
inline int32_t medium_after(const MediumInterface* media, const Vec3f& ng, const Vec3f& w, int32_t current) {
    return media && media->changes_medium() ? media->medium_towards(w, ng) : current;
}

// Scene::intersect with every shape of a scene with media (index-matched boundaries included),
// or as the surface-only estimators do in a scene without.
inline bool intersect_with_boundaries(const Scene& scene, const Ray& ray, Intersection& hit, const MediumInterface*& media) {
    media = nullptr;
    return scene.has_media() ? scene.intersect(ray, hit, kMaskAll, media) : scene.intersect(ray, hit);
}

// The pieces of a walk (what upbp's beam estimators query) are not kept unless asked for.
struct NoPieces {
    template <class... A> void operator()(const A&...) const {}
};

// Follows `ray` from medium `medium` through media and index-matched boundaries. `seg` is
// multiplied by the free-flight weights (and st.r by the channels' densities); `mis_T`, if
// given, by the MIS transmittance of the pieces walked. Each piece in a medium goes to
// on_piece(o, d, length, medium, seg, r, mis_T) before it is walked: from o along the unit d for
// `length` (to where the walk scattered, or to the piece's end), with seg, st.r and the MIS
// transmittance (1 without mis_T) as they stood at o.
template <class T, class OnPiece = NoPieces>
MediumWalk walk_media(const Scene& scene, Ray ray, int32_t medium, MediumState<T>& st, ColourOf<T>& seg, float* mis_T = nullptr,
                      OnPiece&& on_piece = {}) {
    for (int crossings = 0; crossings < kMaxCrossings; ++crossings) {
        MediumWalk w;
        w.dir = ray.d;
        w.medium = medium;
        const bool hit = intersect_with_boundaries(scene, ray, w.isect, w.media);
        if (medium >= 0) {
            const float len = length(ray.d);
            const Vec3f d = ray.d / len;
            const float tmax = hit ? w.isect.t * len : kInf;
            [[maybe_unused]] const ColourOf<T> seg_before = seg, r_before = st.r;
            const FreeFlight ff = sample_free_flight(medium_view(scene.medium(medium), st.wl), ray.o, d, tmax, st.hero_channel(),
                                                     st.rng(), seg, st.r, st.majorant_factor);
            if constexpr (!std::is_same_v<std::decay_t<OnPiece>, NoPieces>)
                on_piece(ray.o, d, ff.scattered ? ff.t : tmax, medium, seg_before, r_before, mis_T ? *mis_T : 1.0f);
            if (mis_T) *mis_T *= mis_transmittance(scene.medium(medium), ray.o, d, ff.scattered ? ff.t : tmax);
            if (ff.scattered) {
                w.kind = MediumWalk::kMedium;
                w.p = ray.o + d * ff.t;
                return w;
            }
            if (is_black(seg)) return {MediumWalk::kLost};
        }
        if (!hit) return w;  // kEscaped
        if (!(w.media && w.media->index_matched)) {
            w.kind = MediumWalk::kSurface;
            return w;
        }
        medium = medium_after(w.media, w.isect.ng, ray.d, medium);
        ray = spawn_ray(w.isect.p, w.isect.ng, ray.d);
    }
    return {MediumWalk::kLost};
}

// The transmittance along a shadow ray (a segment ending a little before its target, or a ray
// to infinity) starting in `medium`: 0 if a surface blocks it, else the product of the media's
// transmittance estimates between the index-matched boundaries it crosses (and, with
// st.pass_null, of the null_transmission of the thin glass and masks it passes). `mis_T`, if given,
// is multiplied by the MIS transmittance of the pieces (left alone when a surface blocks it).
// Each piece in a medium goes to on_piece(medium, length) (the path replay's derivatives of
// homogeneous media: src/diff/path_replay.cpp).
template <class T, class OnPiece = NoPieces>
ColourOf<T> shadow_transmittance(const Scene& scene, Ray shadow, int32_t medium, MediumState<T>& st, float* mis_T = nullptr,
                                 OnPiece&& on_piece = {}) {
    using Colour = ColourOf<T>;
    if (!scene.has_media() && !st.pass_null) return scene.occluded(shadow) ? Colour(0.0f) : Colour(1.0f);
    const bool segment = std::isfinite(shadow.tmax);
    const Vec3f target = shadow.o + shadow.d;  // (segments: d = target - origin)
    Colour Tr(1.0f);
    for (int crossings = 0; crossings < kMaxCrossings; ++crossings) {
        Intersection isect;
        const MediumInterface* media = nullptr;
        const bool hit = intersect_with_boundaries(scene, shadow, isect, media);
        if (hit && !(media && media->index_matched)) {
            const float passed = st.pass_null ? null_transmission(scene, isect, shadow.d) : 0.0f;
            if (!(passed > 0)) return Colour(0.0f);
            Tr *= passed;
        }
        if (medium >= 0) {
            const float len = length(shadow.d);
            const float t = hit ? isect.t : shadow.tmax;
            const float tmax = segment || hit ? t * len : kInf;
            const Medium& m = scene.medium(medium);
            if constexpr (!std::is_same_v<std::decay_t<OnPiece>, NoPieces>) on_piece(medium, tmax);
            if (mis_T) {
                float mis;
                Tr *= estimate_transmittance_with_mis(m, medium_view(m, st.wl), shadow.o, shadow.d / len, tmax, st.rng(), st.majorant_factor, mis);
                *mis_T *= mis;
            } else {
                Tr *= estimate_transmittance(medium_view(m, st.wl), shadow.o, shadow.d / len, tmax, st.rng(), st.majorant_factor);
            }
            if (is_black(Tr)) return Tr;
        }
        if (!hit) return Tr;
        medium = medium_after(media, isect.ng, shadow.d, medium);
        if (segment) {
            const Vec3f from = offset_ray_origin(isect.p, dot(shadow.d, isect.ng) >= 0 ? isect.ng : -isect.ng);
            shadow = Ray{from, target - from, shadow.tmax};
        } else {
            shadow = spawn_ray(isect.p, isect.ng, shadow.d);
        }
    }
    return Colour(0.0f);
}

}  // namespace pathlab
