// pt-naive (course assignment 4A): path tracing by BRDF importance sampling alone. At every
// surface the path adds the emission it finds (front side of an area light) times its
// throughput, samples the BRDF for the next direction, and multiplies the throughput by
// f cos / pdf. An escaping path adds the environment. Point lights are never found, so the
// point-light scenes (0, 1) are black, as the course says.
#include "integrators/common/direct_lighting.hpp"
#include "integrators/integrators.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/common/spectral_shading.hpp"

namespace pathlab {
namespace {

class PtNaive final : public PixelIntegrator {
public:
    explicit PtNaive(const IntegratorOptions& o) : rules_(o), hide_(o.hide_emitters) {}

    Rgb radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler) const override {
        Rgb L(0.0f), beta(1.0f);
        Ray ray = camera_ray;
        for (int bounces = 0;; ++bounces) {
            Intersection hit;
            const bool seen = bounces > 0 || !hide_;
            if (!scene.intersect(ray, hit)) return seen ? L + beta * scene.escaped_radiance(ray.d) : L;
            if (seen) L += beta * emitted_radiance(scene, hit, -normalize(ray.d));
            const ShadingPoint sp = make_shading_point(scene, hit, normalize(ray.d));
            if (sp.material->is_black() || !rules_.may_bounce(bounces)) return L;
            const auto s = sp.material->sample(sp, sp.wi, sampler.next2d());
            if (!s) return L;
            beta *= s->f * (std::abs(s->wo.z) / s->pdfW);
            if (!rules_.survive_roulette(bounces + 1, beta, sampler)) return L;
            ray = sp.spawn(s->wo);
        }
    }

    // Spectral mode: the same path (spectral_shading.hpp), its values at the wavelengths wl.
    Spectrum4 radiance_spectral(const Scene& scene, const Ray& camera_ray, Sampler& sampler, SampledWavelengths& wl) const override {
        Spectrum4 L(0.0f), beta(1.0f);
        Ray ray = camera_ray;
        for (int bounces = 0;; ++bounces) {
            Intersection hit;
            const bool seen = bounces > 0 || !hide_;
            if (!scene.intersect(ray, hit))
                return seen ? L + beta * escaped_spectrum(scene, ray.d, wl) : L;
            if (seen) L += beta * emitted_spectrum(scene, hit, -normalize(ray.d), wl);
            const ShadingPoint sp = make_shading_point(scene, hit, normalize(ray.d));
            if (sp.material->is_black() || !rules_.may_bounce(bounces)) return L;
            const auto s = spectral_sample(sp, sampler.next2d(), wl);
            if (!s) return L;
            beta *= spectral_sample_value(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
            if (!rules_.survive_roulette(bounces + 1, beta, sampler)) return L;
            ray = sp.spawn(s->wo);
        }
    }

private:
    PathRules rules_;
    bool hide_;
};

}  // namespace

const IntegratorInfo& pt_naive_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"pt-naive", {"4a"}, "path tracing by BRDF sampling, Russian roulette", true, true, path_params(),
                         [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> { return std::make_unique<PtNaive>(o); }};
        i.spectral = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab
