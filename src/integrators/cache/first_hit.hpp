// The camera ray's first hit as the caching integrators (ic, pbgi) shade it: at a first hit x on
// a Phong surface (the course's material: Lambertian rho_d plus a Phong lobe) with rho_d > 0,
//   L = emission + direct light (pt-mis's MIS pair: a light sample and a BSDF sample)
//     + rho_d / pi E_indirect(x)                          from the integrator's cache
//     + the Phong lobe's indirect light: the same BSDF sample, weighted by f - rho_d/pi, continued
//       as pt-mis continues a path.
// Elsewhere (other materials, mirrors and glass first, everything after the first hit) it is
// pt-mis. E_indirect excludes light arriving straight from emitters (the direct light's).
// hide_emitters leaves out the paths of no bounce (emitters and the environment seen directly).
#pragma once

#include <optional>

#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/path/pt_mis.hpp"

namespace pathlab {

// The Phong material of sp (at its uv, for a textured one), if it has a diffuse part a cache
// can serve.
inline std::optional<PhongMaterial> cached_diffuse(const ShadingPoint& sp) {
    if (!std::holds_alternative<PhongMaterial>(sp.material->model)) return std::nullopt;
    const PhongMaterial phong = sp.material->varies ? std::get<PhongMaterial>(sp.material->model_at(sp.uv))
                                                    : std::get<PhongMaterial>(sp.material->model);
    if (is_black(phong.diffuse)) return std::nullopt;
    return phong;
}

// indirect_irradiance(sp, sampler, wl) returns E_indirect at the first hit sp in the path's
// colour (wl: its wavelengths).
template <class Wl, typename IndirectIrradiance>
ColourAt<Wl> first_hit_radiance(const Scene& scene, const Ray& ray, Sampler& sampler, const PathRules& rules, Wl& wl,
                                IndirectIrradiance&& indirect_irradiance) {
    using Colour = ColourAt<Wl>;
    Intersection hit;
    if (!scene.intersect(ray, hit)) return rules.hides_emitters() ? Colour(0.0f) : escaped_radiance(scene, ray.d, wl);
    Colour L = rules.hides_emitters() ? Colour(0.0f) : emitted_radiance(scene, hit, -ray.d, wl);
    const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
    const std::optional<PhongMaterial> phong = sp.material->is_black() ? std::nullopt : cached_diffuse(sp);
    if (!phong) return pt_mis_from_hit(scene, hit, ray.d, 0, sampler, rules, wl, false, -1, L);
    if (!rules.may_bounce(0)) return L;
    // Direct light: pt-mis's MIS pair.
    L += estimate_light_sample(scene, sp, sampler, /*mis=*/true, wl);
    const auto s = bsdf_sample(sp, sampler.next2d(), wl);
    EmitterHit found;
    Colour f(0.0f);
    if (s) {
        f = bsdf_sample_colour(sp, *s, wl);
        L += estimate_bsdf_sample_mis(scene, sp, *s, f, found, wl);
    }
    if (!rules.may_bounce(1)) return L;
    // Indirect diffuse light from the cache.
    const Colour rho_d = reflectance_colour(phong->diffuse, wl);
    L += rho_d * kInvPi * indirect_irradiance(sp, sampler, wl);
    // The Phong lobe's indirect light: the BSDF sample, weighted by the lobe alone.
    if (!s || s->delta || !found.hit) return L;
    Colour beta = max(f - rho_d * kInvPi, Colour(0.0f)) * (std::abs(s->wo.z) / s->pdfW);
    if (is_black(beta) || !rules.survive_roulette(1, beta, sampler)) return L;
    return L + beta * pt_mis_from_hit(scene, found.isect, sp.frame.to_world(s->wo), 1, sampler, rules, wl);
}

}  // namespace pathlab
