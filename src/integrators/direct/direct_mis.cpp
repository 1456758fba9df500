// direct-mis (course assignment 3): one light sample and one BRDF sample at the first surface,
// each weighted by the balance heuristic w_a = p_a / (p_light + p_brdf), with both densities
// per unit solid angle of the same direction (p_light includes the light's selection
// probability). The two weights of any one direction sum to 1, so the estimator is unbiased.
// Delta lights are reachable only by light sampling (weight 1); a delta BSDF sample only by
// BSDF sampling (weight 1).
#include "integrators/integrators.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/spectral_direct_lighting.hpp"

namespace pathlab {

namespace {

// Mitsuba's direct: its sample counts must be 1 (one light and one BSDF sample per pass; more
// passes take more), and 0.6's strictNormals is accepted with a note (read_integrator.cpp).
std::vector<ParamInfo> direct_params() {
    return {{"hide_emitters", ParamType::Boolean, "false", "emitters (and the environment) seen directly are black", "hideEmitters"},
            {"shading_samples", ParamType::Integer, "1", "must be 1: pathlab takes one light and one BSDF sample per pixel sample (raise the spp instead)", "shadingSamples"},
            {"emitter_samples", ParamType::Integer, "1", "must be 1 (as shading_samples)", "emitterSamples"},
            {"bsdf_samples", ParamType::Integer, "1", "must be 1 (as shading_samples)", "bsdfSamples"},
            {"strict_normals", ParamType::Boolean, "false", "accepted and ignored (noted): pathlab's shading-normal handling is its own", "strictNormals"}};
}

class DirectMis final : public PixelIntegrator {
public:
    explicit DirectMis(bool hide) : hide_(hide) {}
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return hide_ ? Rgb(0.0f) : scene.escaped_radiance(ray.d);
        Rgb L = hide_ ? Rgb(0.0f) : emitted_radiance(scene, hit, -ray.d);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        if (sp.material->is_black()) return L;
        L += estimate_light_sample(scene, sp, sampler, /*mis=*/true);
        if (!scene.has_hittable_emitters()) return L;  // only delta lights: the BSDF ray finds nothing
        if (const auto s = sp.material->sample(sp, sp.wi, sampler.next2d())) {
            EmitterHit found;
            L += estimate_bsdf_sample_mis(scene, sp, *s, found);
        }
        return L;
    }
    // Spectral mode: the same samples, their values at the wavelengths wl (spectral_direct_lighting.hpp).
    Spectrum4 radiance_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, SampledWavelengths& wl) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return hide_ ? Spectrum4(0.0f) : escaped_spectrum(scene, ray.d, wl);
        Spectrum4 L = hide_ ? Spectrum4(0.0f) : emitted_spectrum(scene, hit, -ray.d, wl);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        if (sp.material->is_black()) return L;
        L += estimate_light_sample_spectral(scene, sp, sampler, /*mis=*/true, wl);
        if (!scene.has_hittable_emitters()) return L;
        if (const auto s = spectral_sample(sp, sampler.next2d(), wl)) {
            EmitterHit found;
            L += estimate_bsdf_sample_mis_spectral(scene, sp, *s, spectral_sample_value(sp, *s, wl), found, wl);
        }
        return L;
    }

private:
    bool hide_;
};

}  // namespace

const IntegratorInfo& direct_mis_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"direct-mis", {"3", "direct"}, "light + BRDF sampling combined by MIS (balance heuristic)",
                         false, true, direct_params(), [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
                             return std::make_unique<DirectMis>(o.hide_emitters);
                         }};
        i.spectral = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
