// eyelight: a debugging view. Each pixel shows |cos| between the camera ray and the surface
// normal it hits (black where the ray escapes). No lights, no materials.
#include "integrators/integrators.hpp"
#include "integrators/common/spectral_shading.hpp"

namespace pathlab {
namespace {

class EyeLight final : public PixelIntegrator {
public:
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler&) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return Rgb(0.0f);
        return Rgb(std::abs(dot(ray.d, hit.ns)));
    }
    // Spectral mode: |cos| times the spectrum of an RGB white emitter (D65 at unit luminance,
    // through emission_spectrum with no light), so the view stays grey in the film.
    Spectrum4 radiance_spectral(const Scene& scene, const Ray& ray, Sampler&, SampledWavelengths& wl) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return Spectrum4(0.0f);
        return emission_spectrum(scene, -1, Rgb(1.0f), wl) * std::abs(dot(ray.d, hit.ns));
    }
};

}  // namespace

const IntegratorInfo& eyelight_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"eyelight", {}, "debug view: |cos| between camera ray and surface normal", false, true, {},
                         [](const IntegratorOptions&) -> std::unique_ptr<Integrator> { return std::make_unique<EyeLight>(); }};
        i.spectral = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
