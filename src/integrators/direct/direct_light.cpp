// direct-light (course assignment 1): direct illumination by explicit light sampling.
// At the first surface a camera ray hits: its own emission (if it is an area light, seen from
// the front) plus one light sample (light chosen by power, see Scene::choose_light) with a
// shadow ray. Rays that escape return the environment's radiance.
#include "integrators/integrators.hpp"
#include "integrators/common/direct_lighting.hpp"

namespace pathlab {
namespace {

template <class T>
class DirectLight final : public PixelIntegrator<T> {
public:
    explicit DirectLight(const IntegratorOptions& o) : hide_(o.hide_emitters) {}
    ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const override {
        ColourOf<T> L;
        const auto sp = first_surface(scene, ray, hide_, wl, L);
        if (!sp) return L;
        return L + estimate_light_sample(scene, *sp, sampler, /*mis=*/false, wl);
    }

private:
    bool hide_;
};

}  // namespace

const IntegratorInfo& direct_light_integrator() {
    static const IntegratorInfo info = sampling_lights(IntegratorInfo{"direct-light", {"1"}, "direct illumination by light sampling (one light chosen by power)",
                         false, true, {{"hide_emitters", ParamType::Boolean, "false", "emitters (and the environment) seen directly are black", "hideEmitters"}},
                         [](const IntegratorOptions& o) { return make_for_transport<DirectLight>(o); }});
    return info;
}

}  // namespace pathlab
