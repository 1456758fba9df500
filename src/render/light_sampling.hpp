// Next-event estimation, shared by every estimator that samples lights explicitly.
#pragma once

#include "core/rng.hpp"
#include "core/sampling.hpp"
#include "render/shading.hpp"

namespace pathlab {

// One light chosen with probability proportional to power, one point or direction sampled on
// it, one shadow ray. Returns f * Le * cos(theta) / (pmf * pdfW). With `mis`, the result is
// weighted by the balance heuristic against BSDF sampling of the same direction (both
// densities in solid angle, the light's including its selection probability); delta lights
// cannot be found by BSDF sampling and keep weight 1.
inline Rgb estimate_light_sample(const Scene& scene, const ShadingPoint& sp, Sampler& sampler, bool mis) {
    const LightChoice choice = scene.choose_light(sampler.next1d());
    const Vec2f u = sampler.next2d();
    if (choice.index < 0) return Rgb(0.0f);
    const auto ls = sample_light(scene.lights()[size_t(choice.index)], sp.p, u);
    if (!ls || is_black(ls->Le) || dot(ls->wi, sp.ng) <= 0) return Rgb(0.0f);
    const Vec3f wo = sp.frame.to_local(ls->wi);
    const Rgb f = sp.material->eval(sp.wi, wo);
    if (is_black(f)) return Rgb(0.0f);
    const Ray shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi)
                                                : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
    if (scene.occluded(shadow)) return Rgb(0.0f);
    const float pdf_light = choice.pmf * ls->pdfW;
    const float weight = (mis && !ls->delta) ? balance_heuristic(pdf_light, sp.material->pdf(sp.wi, wo)) : 1.0f;
    return f * ls->Le * (std::abs(wo.z) * weight / pdf_light);
}

}  // namespace pathlab
