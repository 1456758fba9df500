// Direct illumination by sampling directions at the first surface (course assignments 2A-2C):
//   direct-uniform (2a): uniform hemisphere around the shading normal, pdfW = 1 / (2 pi)
//   direct-cosine  (2b): cosine-weighted hemisphere, pdfW = cos(theta) / pi
//   direct-brdf    (2c): the material's own sampling (Phong: lobe mixture, see phong.hpp)
// The sampled ray adds f Le cos / pdfW if it hits the front of an area light or escapes to the
// environment. A point light is never hit by a sampled direction, so these estimators are
// black in scenes lit only by point lights (0, 1): correct, and why MIS exists.
#include "integrators/integrators.hpp"
#include "integrators/common/direct_lighting.hpp"

namespace pathlab {
namespace {

enum class Strategy { UniformHemisphere, CosineHemisphere, Brdf };

template <class T>
class DirectBySampling final : public PixelIntegrator<T> {
public:
    DirectBySampling(const IntegratorOptions& o, Strategy s) : strategy_(s), hide_(o.hide_emitters) {}

    ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const override {
        using Colour = ColourOf<T>;
        Colour L;
        const auto first = first_surface(scene, ray, hide_, wl, L);
        if (!first) return L;
        const ShadingPoint& sp = *first;

        const Vec2f u = sampler.next2d();
        Vec3f wo;
        Colour f;
        float pdfW = 0;
        switch (strategy_) {
            case Strategy::UniformHemisphere:
                wo = square_to_uniform_hemisphere(u);
                pdfW = uniform_hemisphere_pdf(wo);
                f = bsdf_eval(sp, wo, wl);
                break;
            case Strategy::CosineHemisphere:
                wo = square_to_cosine_hemisphere(u);
                pdfW = cosine_hemisphere_pdf(wo);
                f = bsdf_eval(sp, wo, wl);
                break;
            case Strategy::Brdf: {
                const auto s = bsdf_sample(sp, u, wl);
                if (!s) return L;
                wo = s->wo, f = bsdf_sample_colour(sp, *s, wl), pdfW = s->pdfW;
                break;
            }
        }
        if (!(pdfW > 0) || is_black(f)) return L;
        const EmitterHit e = trace_to_emitter(scene, sp.spawn(wo), sp.p, sp.frame.n);
        if (is_black(e.Le)) return L;
        const int light = e.hit ? e.isect.light : scene.environment_light();
        return L + f * light_colour(scene, light, e.Le, wl) * (std::abs(wo.z) / pdfW);
    }

private:
    Strategy strategy_;
    bool hide_;
};

}  // namespace

namespace {

IntegratorInfo direct_sampling_info(const char* name, const char* alias, const char* summary, Strategy strategy) {
    return {name, {alias}, summary, true, true,
            {{"hide_emitters", ParamType::Boolean, "false", "emitters (and the environment) seen directly are black", "hideEmitters"}},
            [strategy](const IntegratorOptions& o) { return make_for_transport<DirectBySampling>(o, strategy); }};
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
