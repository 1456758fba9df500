// direct_lighting.hpp's estimators in spectral mode: the same samples, rays, densities and MIS
// weights (so the same random numbers in the same order), with the BSDF's value and the
// emitters' radiance at the path's wavelengths (spectral_shading.hpp).
#pragma once

#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/spectral_shading.hpp"

namespace pathlab {

// estimate_light_sample at the wavelengths wl.
inline Spectrum4 estimate_light_sample_spectral(const Scene& scene, const ShadingPoint& sp, Sampler& sampler, bool mis,
                                                SampledWavelengths& wl) {
    const LightChoice choice = scene.choose_light(sampler.next1d());
    const Vec2f u = sampler.next2d();
    if (choice.index < 0) return Spectrum4(0.0f);
    const auto ls = sample_light(scene.lights()[size_t(choice.index)], sp.p, u);
    if (!ls || is_black(ls->Le)) return Spectrum4(0.0f);
    if (dot(ls->wi, sp.ng) <= 0 && !sp.material->is_dielectric()) return Spectrum4(0.0f);
    const Vec3f wo = sp.frame.to_local(ls->wi);
    // The BSDF in RGB first (as RGB mode, so a shadow ray is traced where it would be), its
    // spectral value once the light is known to be visible; a dispersive interface (which
    // reduces wl to the hero) at once.
    float pdf_bsdf;
    const bool dispersive = is_dispersive(*sp.material);
    Spectrum4 f(0.0f);
    Rgb f_rgb(0.0f);
    if (dispersive) [[unlikely]] {
        f = spectral_eval_and_pdf(sp, wo, wl, pdf_bsdf);
        if (f.is_black()) return Spectrum4(0.0f);
    } else {
        f_rgb = sp.material->eval_and_pdf(sp, sp.wi, wo, pdf_bsdf);
        if (is_black(f_rgb)) return Spectrum4(0.0f);
    }
    const Ray shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi)
                                                : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
    if (scene.occluded(shadow)) return Spectrum4(0.0f);
    if (!dispersive) f = spectral_eval(sp, wo, f_rgb, wl);
    const float pdf_light = choice.pmf * ls->pdfW;
    const float weight = (mis && !ls->delta) ? balance_heuristic(pdf_light, pdf_bsdf) : 1.0f;
    return f * emission_spectrum(scene, choice.index, ls->Le, wl) * (std::abs(wo.z) * weight / pdf_light);
}

// estimate_bsdf_sample_mis at the wavelengths wl; `f` is the sample's value there.
inline Spectrum4 estimate_bsdf_sample_mis_spectral(const Scene& scene, const ShadingPoint& sp, const BsdfSample& s, const Spectrum4& f,
                                                   EmitterHit& found, const SampledWavelengths& wl) {
    found = trace_to_emitter(scene, sp.spawn(s.wo), sp.p);
    if (is_black(found.Le)) return Spectrum4(0.0f);
    const float weight = s.delta ? 1.0f : balance_heuristic(s.pdfW, found.pdf_light);
    const int light = found.hit ? found.isect.light : scene.environment_light();
    return f * emission_spectrum(scene, light, found.Le, wl) * (std::abs(s.wo.z) * weight / s.pdfW);
}

}  // namespace pathlab
