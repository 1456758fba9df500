// eyelight: a debugging view. Each pixel shows |cos| between the camera ray and the surface
// normal it hits (black where the ray escapes). No lights, no materials.
#include "integrators/integrators.hpp"

namespace pathlab {
namespace {

class EyeLight final : public PixelIntegrator {
public:
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler&) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return Rgb(0.0f);
        return Rgb(std::abs(dot(ray.d, hit.ns)));
    }
};

}  // namespace

const IntegratorInfo& eyelight_integrator() {
    static const IntegratorInfo info{"eyelight", {}, "debug view: |cos| between camera ray and surface normal", false, true, {},
                                     [](const IntegratorOptions&) -> std::unique_ptr<Integrator> { return std::make_unique<EyeLight>(); }};
    return info;
}

}  // namespace pathlab
