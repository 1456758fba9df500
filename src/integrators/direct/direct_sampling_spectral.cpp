// direct-uniform, direct-cosine and direct-brdf in spectral mode: the same direction (the same
// random number) as RGB mode's, the BSDF's value and the emission found at the wavelengths wl
// (spectral_shading.hpp).
#include "integrators/direct/direct_sampling_spectral.hpp"

#include "core/sampling.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/spectral_shading.hpp"

namespace pathlab {

Spectrum4 direct_sampling_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, SampledWavelengths& wl, DirectSamplingStrategy strategy,
                                   bool hide) {
    Intersection hit;
    if (!scene.intersect(ray, hit)) return hide ? Spectrum4(0.0f) : escaped_spectrum(scene, ray.d, wl);
    Spectrum4 L = hide ? Spectrum4(0.0f) : emitted_spectrum(scene, hit, -ray.d, wl);
    const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
    if (sp.material->is_black()) return L;

    const Vec2f u = sampler.next2d();
    Vec3f wo;
    Spectrum4 f(0.0f);
    float pdfW = 0;
    switch (strategy) {
        case DirectSamplingStrategy::UniformHemisphere:
        case DirectSamplingStrategy::CosineHemisphere: {
            const bool uniform = strategy == DirectSamplingStrategy::UniformHemisphere;
            wo = uniform ? square_to_uniform_hemisphere(u) : square_to_cosine_hemisphere(u);
            pdfW = uniform ? uniform_hemisphere_pdf(wo) : cosine_hemisphere_pdf(wo);
            float pdf_bsdf;  // (unused: these strategies do not sample the BSDF)
            f = spectral_eval_and_pdf(sp, wo, wl, pdf_bsdf);
            break;
        }
        case DirectSamplingStrategy::Brdf: {
            const auto s = spectral_sample(sp, u, wl);
            if (!s) return L;
            wo = s->wo, f = spectral_sample_value(sp, *s, wl), pdfW = s->pdfW;
            break;
        }
    }
    if (!(pdfW > 0) || f.is_black()) return L;
    const EmitterHit e = trace_to_emitter(scene, sp.spawn(wo), sp.p);
    if (is_black(e.Le)) return L;
    const int light = e.hit ? e.isect.light : scene.environment_light();
    return L + f * emission_spectrum(scene, light, e.Le, wl) * (std::abs(wo.z) / pdfW);
}

}  // namespace pathlab
