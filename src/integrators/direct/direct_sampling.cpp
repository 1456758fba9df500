// Direct illumination by sampling directions at the first surface (course assignments 2A-2C):
//   direct-uniform (2a): uniform hemisphere around the shading normal, pdfW = 1 / (2 pi)
//   direct-cosine  (2b): cosine-weighted hemisphere, pdfW = cos(theta) / pi
//   direct-brdf    (2c): the material's own sampling (Phong: lobe mixture, see phong.hpp)
// The sampled ray adds f Le cos / pdfW if it hits the front of an area light or escapes to the
// environment. A point light is never hit by a sampled direction, so these estimators are
// black in scenes lit only by point lights (0, 1): correct, and why MIS exists.
#include "integrators/integrators.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "integrators/direct/direct_sampling_spectral.hpp"

namespace pathlab {
namespace {

enum class Strategy { UniformHemisphere, CosineHemisphere, Brdf };
static_assert(int(Strategy::UniformHemisphere) == int(DirectSamplingStrategy::UniformHemisphere) &&
              int(Strategy::CosineHemisphere) == int(DirectSamplingStrategy::CosineHemisphere) &&
              int(Strategy::Brdf) == int(DirectSamplingStrategy::Brdf));

class DirectBySampling final : public PixelIntegrator {
public:
    DirectBySampling(Strategy s, bool hide) : strategy_(s), hide_(hide) {}

    Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return hide_ ? Rgb(0.0f) : scene.escaped_radiance(ray.d);
        Rgb L = hide_ ? Rgb(0.0f) : emitted_radiance(scene, hit, -ray.d);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        if (sp.material->is_black()) return L;

        const Vec2f u = sampler.next2d();
        Vec3f wo;
        Rgb f;
        float pdfW = 0;
        switch (strategy_) {
            case Strategy::UniformHemisphere:
                wo = square_to_uniform_hemisphere(u);
                pdfW = uniform_hemisphere_pdf(wo);
                f = sp.material->eval(sp, sp.wi, wo);
                break;
            case Strategy::CosineHemisphere:
                wo = square_to_cosine_hemisphere(u);
                pdfW = cosine_hemisphere_pdf(wo);
                f = sp.material->eval(sp, sp.wi, wo);
                break;
            case Strategy::Brdf: {
                const auto s = sp.material->sample(sp, sp.wi, u);
                if (!s) return L;
                wo = s->wo, f = s->f, pdfW = s->pdfW;
                break;
            }
        }
        if (!(pdfW > 0) || is_black(f)) return L;
        const EmitterHit e = trace_to_emitter(scene, sp.spawn(wo), sp.p);
        return L + f * e.Le * (std::abs(wo.z) / pdfW);
    }

    // Spectral mode (direct_sampling_spectral.cpp, a file of its own so that this one compiles as before).
    Spectrum4 radiance_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, SampledWavelengths& wl) const override {
        return direct_sampling_spectral(scene, ray, sampler, wl, DirectSamplingStrategy(int(strategy_)), hide_);
    }

private:
    Strategy strategy_;
    bool hide_;
};

}  // namespace

namespace {

IntegratorInfo direct_sampling_info(const char* name, const char* alias, const char* summary, Strategy strategy) {
    IntegratorInfo i{name, {alias}, summary, true, true,
                     {{"hide_emitters", ParamType::Boolean, "false", "emitters (and the environment) seen directly are black", "hideEmitters"}},
                     [strategy](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
                         return std::make_unique<DirectBySampling>(strategy, o.hide_emitters);
                     }};
    i.spectral = true;
    return i;
}

}  // namespace

const IntegratorInfo& direct_uniform_integrator() {
    static const IntegratorInfo info =
        direct_sampling_info("direct-uniform", "2a", "direct illumination by uniform hemisphere sampling", Strategy::UniformHemisphere);
    return info;
}
const IntegratorInfo& direct_cosine_integrator() {
    static const IntegratorInfo info = direct_sampling_info("direct-cosine", "2b", "direct illumination by cosine-weighted hemisphere sampling",
                                                            Strategy::CosineHemisphere);
    return info;
}
const IntegratorInfo& direct_brdf_integrator() {
    static const IntegratorInfo info =
        direct_sampling_info("direct-brdf", "2c", "direct illumination by BRDF importance sampling", Strategy::Brdf);
    return info;
}

}  // namespace pathlab
