// direct-mis (course assignment 3): one light sample and one BRDF sample at the first surface,
// each weighted by the balance heuristic w_a = p_a / (p_light + p_brdf), with both densities
// per unit solid angle of the same direction (p_light includes the light's selection
// probability). The two weights of any one direction sum to 1, so the estimator is unbiased.
// Delta lights are reachable only by light sampling (weight 1); a delta BSDF sample only by
// BSDF sampling (weight 1).
#include "integrators/integrators.hpp"
#include "integrators/common/direct_lighting.hpp"

namespace pathlab {

namespace {

class DirectMis final : public PixelIntegrator {
public:
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return scene.escaped_radiance(ray.d);
        Rgb L = emitted_radiance(scene, hit, -ray.d);
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
};

}  // namespace

const IntegratorInfo& direct_mis_integrator() {
    static const IntegratorInfo info{"direct-mis", {"3", "direct"}, "light + BRDF sampling combined by MIS (balance heuristic)",
                                     false, true, {}, [](const IntegratorOptions&) -> std::unique_ptr<Integrator> {
                                         return std::make_unique<DirectMis>();
                                     }};
    return info;
}

}  // namespace pathlab
