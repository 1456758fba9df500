// first_hit.hpp's first-hit shading in spectral mode (docs/spectral.md, "Spectral ic and pbgi"):
// the same random numbers in the same order, emission, direct light, the Phong lobe's indirect
// light and every path pt-mis continues at the wavelengths wl; the cached indirect diffuse light
// comes from indirect_irradiance(sp, sampler, wl), which may turn a cache's RGB into a spectrum.
#pragma once

#include "integrators/cache/first_hit.hpp"
#include "integrators/common/spectral_direct_lighting.hpp"
#include "integrators/path/pt_mis_spectral.hpp"

namespace pathlab {

template <typename IndirectIrradiance>
Spectrum4 first_hit_radiance_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, const PathRules& rules, bool hide_emitters,
                                      SampledWavelengths& wl, IndirectIrradiance&& indirect_irradiance) {
    Intersection hit;
    if (!scene.intersect(ray, hit)) return hide_emitters ? Spectrum4(0.0f) : escaped_spectrum(scene, ray.d, wl);
    Spectrum4 L = hide_emitters ? Spectrum4(0.0f) : emitted_spectrum(scene, hit, -ray.d, wl);
    const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
    const std::optional<PhongMaterial> phong = sp.material->is_black() ? std::nullopt : cached_diffuse(sp);
    if (!phong) return pt_mis_spectral_from_hit(scene, hit, ray.d, 0, sampler, rules, false, -1, L, wl);
    if (!rules.may_bounce(0)) return L;
    L += estimate_light_sample_spectral(scene, sp, sampler, /*mis=*/true, wl);
    const auto s = spectral_sample(sp, sampler.next2d(), wl);
    EmitterHit found;
    Spectrum4 f(0.0f);
    if (s) {
        f = spectral_sample_value(sp, *s, wl);
        L += estimate_bsdf_sample_mis_spectral(scene, sp, *s, f, found, wl);
    }
    if (!rules.may_bounce(1)) return L;
    const Spectrum4 rho_d = reflectance_spectrum(phong->diffuse, wl);
    L += rho_d * kInvPi * indirect_irradiance(sp, sampler, wl);
    if (!s || s->delta || !found.hit) return L;
    // The Phong lobe alone: f minus the diffuse part, at the same wavelengths.
    Spectrum4 beta = max(f - rho_d * kInvPi, Spectrum4(0.0f)) * (std::abs(s->wo.z) / s->pdfW);
    if (beta.is_black() || !rules.survive_roulette(1, beta, sampler)) return L;
    return L + beta * pt_mis_spectral_from_hit(scene, found.isect, sp.frame.to_world(s->wo), 1, sampler, rules, false, -1, Spectrum4(0.0f), wl);
}

}  // namespace pathlab
