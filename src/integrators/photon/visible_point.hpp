// The camera side of the photon methods (sppm, pm): a camera ray followed through Dirac lobes
// (mirrors, glass, plastic's coating) to its first other surface, the visible point, where the
// photons are gathered. Emission found on the way is added to L: there it is seen directly or
// through Dirac lobes only, and no other strategy has it.
#pragma once

#include <optional>

#include "integrators/common/direct_lighting.hpp"

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

}  // namespace pathlab
