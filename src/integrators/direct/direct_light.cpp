// direct-light (course assignment 1): direct illumination by explicit light sampling.
// At the first surface a camera ray hits: its own emission (if it is an area light, seen from
// the front) plus one light sample (light chosen by power, see Scene::choose_light) with a
// shadow ray. Rays that escape return the environment's radiance.
#include "integrators/integrators.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/spectral_direct_lighting.hpp"

namespace pathlab {
namespace {

class DirectLight final : public PixelIntegrator {
public:
    explicit DirectLight(bool hide) : hide_(hide) {}
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return hide_ ? Rgb(0.0f) : scene.escaped_radiance(ray.d);
        Rgb L = hide_ ? Rgb(0.0f) : emitted_radiance(scene, hit, -ray.d);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        if (sp.material->is_black()) return L;
        return L + estimate_light_sample(scene, sp, sampler, /*mis=*/false);
    }
    // Spectral mode: the same samples, their values at the wavelengths wl (spectral_direct_lighting.hpp).
    Spectrum4 radiance_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, SampledWavelengths& wl) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return hide_ ? Spectrum4(0.0f) : escaped_spectrum(scene, ray.d, wl);
        Spectrum4 L = hide_ ? Spectrum4(0.0f) : emitted_spectrum(scene, hit, -ray.d, wl);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        if (sp.material->is_black()) return L;
        return L + estimate_light_sample_spectral(scene, sp, sampler, /*mis=*/false, wl);
    }

private:
    bool hide_;
};

}  // namespace

const IntegratorInfo& direct_light_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"direct-light", {"1"}, "direct illumination by light sampling (one light chosen by power)",
                         false, true, {{"hide_emitters", ParamType::Boolean, "false", "emitters (and the environment) seen directly are black", "hideEmitters"}}, [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
                             return std::make_unique<DirectLight>(o.hide_emitters);
                         }};
        i.spectral = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
