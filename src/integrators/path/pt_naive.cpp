// pt-naive (course assignment 4A): path tracing by BRDF importance sampling alone. At every
// surface the path adds the emission it finds (front side of an area light) times its
// throughput, samples the BRDF for the next direction, and multiplies the throughput by
// f cos / pdf. An escaping path adds the environment. Point lights are never found, so the
// point-light scenes (0, 1) are black, as the course says.
#include "integrators/common/direct_lighting.hpp"
#include "integrators/integrators.hpp"
#include "integrators/common/path_rules.hpp"

namespace pathlab {
namespace {

template <class T>
class PtNaive final : public PixelIntegrator<T> {
public:
    explicit PtNaive(const IntegratorOptions& o) : rules_(o), hide_(o.hide_emitters) {}

    ColourOf<T> radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, WavelengthsOf<T>& wl) const override {
        ColourOf<T> L(0.0f), beta(1.0f);
        Ray ray = camera_ray;
        for (int bounces = 0;; ++bounces) {
            Intersection hit;
            const bool seen = bounces > 0 || !hide_;
            if (!scene.intersect(ray, hit)) return seen ? L + beta * escaped_radiance(scene, ray.d, wl) : L;
            if (seen) L += beta * emitted_radiance(scene, hit, -normalize(ray.d), wl);
            const ShadingPoint sp = make_shading_point(scene, hit, normalize(ray.d));
            if (sp.material->is_black() || !rules_.may_bounce(bounces)) return L;
            const auto s = bsdf_sample(sp, sampler.next2d(), wl);
            if (!s) return L;
            beta *= bsdf_sample_colour(sp, *s, wl) * (std::abs(s->wo.z) / s->pdfW);
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
    static const IntegratorInfo info{"pt-naive", {"4a"}, "path tracing by BRDF sampling, Russian roulette", true, true, path_params(),
                                     [](const IntegratorOptions& o) { return make_for_transport<PtNaive>(o); }};
    return info;
}

}  // namespace pathlab
