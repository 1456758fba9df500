// direct-light (course assignment 1): direct illumination by explicit light sampling.
// At the first surface a camera ray hits: its own emission (if it is an area light, seen from
// the front) plus one light sample (light chosen by power, see Scene::choose_light) with a
// shadow ray. Rays that escape return the environment's radiance.
#include "integrators/integrators.hpp"
#include "integrators/common/direct_lighting.hpp"

namespace pathlab {
namespace {

class DirectLight final : public PixelIntegrator {
public:
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return scene.escaped_radiance(ray.d);
        Rgb L = emitted_radiance(scene, hit, -ray.d);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        if (sp.material->is_black()) return L;
        return L + estimate_light_sample(scene, sp, sampler, /*mis=*/false);
    }
};

}  // namespace

const IntegratorInfo& direct_light_integrator() {
    static const IntegratorInfo info{"direct-light", {"1"}, "direct illumination by light sampling (one light chosen by power)",
                                     false, true, {}, [](const IntegratorOptions&) -> std::unique_ptr<Integrator> {
                                         return std::make_unique<DirectLight>();
                                     }};
    return info;
}

}  // namespace pathlab
