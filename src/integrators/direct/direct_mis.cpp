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

// Mitsuba's direct: its sample counts must be 1 (one light and one BSDF sample per pass; more
// passes take more), and 0.6's strictNormals is accepted with a note (read_integrator.cpp).
std::vector<ParamInfo> direct_params() {
    return {{"hide_emitters", ParamType::Boolean, "false", "emitters (and the environment) seen directly are black", "hideEmitters"},
            {"shading_samples", ParamType::Integer, "1", "must be 1: pathlab takes one light and one BSDF sample per pixel sample (raise the spp instead)", "shadingSamples"},
            {"emitter_samples", ParamType::Integer, "1", "must be 1 (as shading_samples)", "emitterSamples"},
            {"bsdf_samples", ParamType::Integer, "1", "must be 1 (as shading_samples)", "bsdfSamples"},
            {"strict_normals", ParamType::Boolean, "false", "accepted and ignored (noted): pathlab's shading-normal handling is its own", "strictNormals"}};
}

template <class T>
class DirectMis final : public PixelIntegrator<T> {
public:
    explicit DirectMis(const IntegratorOptions& o) : hide_(o.hide_emitters), power_(o.mis_power) {}
    ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler& sampler, WavelengthsOf<T>& wl) const override {
        ColourOf<T> L;
        const auto first = first_surface(scene, ray, hide_, wl, L);
        if (!first) return L;
        const ShadingPoint& sp = *first;
        L += estimate_light_sample(scene, sp, sampler, /*mis=*/true, wl, power_);
        if (!scene.has_hittable_emitters()) return L;  // only delta lights: the BSDF ray finds nothing
        if (const auto s = bsdf_sample(sp, sampler.next2d(), wl)) {
            EmitterHit found;
            L += estimate_bsdf_sample_mis(scene, sp, *s, bsdf_sample_colour(sp, *s, wl), found, wl, power_);
        }
        return L;
    }

private:
    bool hide_;
    bool power_;
};

}  // namespace

const IntegratorInfo& direct_mis_integrator() {
    static const IntegratorInfo info = sampling_lights(IntegratorInfo{"direct-mis", {"3", "direct"}, "light + BRDF sampling combined by MIS (balance heuristic)",
                         false, true, direct_params(), [](const IntegratorOptions& o) { return make_for_transport<DirectMis>(o); }});
    return info;
}

}  // namespace pathlab
