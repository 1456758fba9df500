// The light sample of next-event estimation, drawn by the scene's light sampler, or with
// --light-sampler ris by resampled importance sampling (Talbot, Cline and Egbert 2005, "Importance
// resampling for global illumination"; ReSTIR-DI's candidate resampling without reuse):
//   M candidates x_1..x_M, each a light chosen by the bvh sampler and a point or direction sampled
//   on it, with source density p(x) = pmf * pdfW (solid angle; a Dirac coefficient for delta
//   lights); weights w_i = t(x_i) / p(x_i), where the target t is the magnitude of the unshadowed
//   contribution (BSDF or phase function, times Le, times the cosine: no visibility); one
//   candidate y kept with probability w_y / sum w, and one shadow ray to it. Talbot's estimate
//   g(y) / t(y) * (1/M) sum w_i is unbiased for any g that is zero wherever t is: the caller
//   divides g(y) by `pdf` = t(y) M / sum w as it would divide by p.
// MIS: the caller weighs g by the balance heuristic of the source density p (`pdf_source`)
// against the BSDF's, and the BSDF-sampled half weighs an emitter it hits with the same p
// (Scene::light_pmf): the two weights sum to one for every direction and each half is unbiased
// on its own weighted integrand, so the sum is. (Not the optimal weights: RIS's own density,
// which has no closed form, is higher where t is.)
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "lights/light.hpp"
#include "samplers/sampler.hpp"
#include "scene/scene.hpp"

namespace pathlab {

struct NeeSample {
    LightChoice choice;
    LightSample ls;
    float pdf = 0;         // what the estimate divides by
    float pdf_source = 0;  // pmf * pdfW: the density MIS weighs with
};

// `target(ls, light)` is t for a candidate; `candidates` >= 2 (one is the light sampler's own
// sample: for_each_nee_sample).
template <class Target>
std::optional<NeeSample> resample_nee(const Scene& scene, const Vec3f& p, const Vec3f& n, Sampler& sampler, int candidates,
                                      Target&& target) {
    // A weighted reservoir of one (Chao's algorithm): candidate i replaces the kept one with
    // probability w_i / (w_1 + ... + w_i), decided by one uniform number that each decision
    // rescales to a fresh uniform number (in double: 8 candidates use a few of its 53 bits).
    // Only the kept candidate's light and point numbers are kept; its sample is drawn again.
    double u = sampler.next1d();
    LightChoice kept;
    Vec2f kept_u;
    float kept_t = 0, sum = 0;
    const int m = std::min(candidates, kMaxRisCandidates);
    for (int i = 0; i < m; ++i) {
        const LightChoice choice = scene.choose_light(p, n, sampler.next1d());
        const Vec2f uv = sampler.next2d();
        if (choice.index < 0) continue;
        const auto ls = sample_light(scene.lights()[size_t(choice.index)], p, uv);
        if (!ls || is_black(ls->Le)) continue;
        const float t = target(*ls, choice.index);
        const float w = t / (choice.pmf * ls->pdfW);
        if (!(t > 0) || !std::isfinite(w)) continue;  // t = 0: g is zero there too
        sum += w;
        const double q = double(w) / double(sum);
        if (u < q) {
            kept = choice, kept_u = uv, kept_t = t;
            u /= q;
        } else {
            u = (u - q) / (1 - q);
        }
    }
    if (!(sum > 0)) return std::nullopt;
    const auto ls = sample_light(scene.lights()[size_t(kept.index)], p, kept_u);
    return NeeSample{kept, *ls, kept_t * float(m) / sum, kept.pmf * ls->pdfW};
}

// Next-event estimation's light samples at a point: ris's one (candidates > 1), else the light
// sampler's: one light, or with adaptive splitting (--light-split, light_sampler.hpp) each light
// choose_split returns, every one drawn with the same random numbers (a 1D choice, then a 2D
// point: each sample is unbiased for its part of the lights, and their sum for all).
// f(const NeeSample&) for each. Splitting is for the camera path's first vertex (`split`; a path
// tracer's later vertices choose one light: their extra shadow rays cost more than they gain,
// docs/lights.md); the MIS partner at the vertex reads the pmf of the same choice
// (Scene::light_pmf's `split`).
template <class Target, class F>
void for_each_nee_sample(const Scene& scene, const Vec3f& p, const Vec3f& n, Sampler& sampler, int candidates, Target&& target, F&& f,
                         bool split = true) {
    if (candidates > 1) {
        if (const auto nee = resample_nee(scene, p, n, sampler, candidates, target)) f(*nee);
        return;
    }
    LightChoice chosen[kMaxSplitLights];
    const int count = scene.light_sampler().choose_split(p, n, sampler.next1d(), chosen, split);
    const Vec2f u = sampler.next2d();
    for (int i = 0; i < count; ++i) {
        const auto ls = sample_light(scene.lights()[size_t(chosen[i].index)], p, u);
        if (!ls || is_black(ls->Le)) continue;
        const float pdf = chosen[i].pmf * ls->pdfW;
        f(NeeSample{chosen[i], *ls, pdf, pdf});
    }
}

}  // namespace pathlab
