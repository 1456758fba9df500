// Path tracing with next-event estimation combined by MIS (course assignments 4B and 4C).
// At every surface x_k the path adds, times its throughput, what direct-mis adds there: a
// light sample and a BSDF sample, each weighted by the balance heuristic (--mis power: the power
// heuristic, as Mitsuba's path tracer weighs them). Emission seen
// directly by the camera is added once, at x_0.
//
//   pt-mis3 (4b): three rays per bounce. The MIS BSDF sample is one ray; a third, independent
//     BSDF sample continues the path. The emission the continuation ray finds is not counted
//     (it was already accounted for by the MIS pair at the previous vertex).
//   pt-mis  (4c): two rays per bounce. The MIS BSDF sample both contributes its weighted
//     emission and continues the path, so the surface it finds is the next vertex.
#include "integrators/path/pt_mis.hpp"

#include "integrators/common/direct_lighting.hpp"
#include "integrators/integrators.hpp"

namespace pathlab {

template <class Wl>
ColourAt<Wl> pt_mis_from_hit(const Scene& scene, Intersection hit, Vec3f dir, int first_bounce, Sampler& sampler, const PathRules& rules,
                             Wl& wl, bool three_rays, int only_length, ColourAt<Wl> L) {
    using Colour = ColourAt<Wl>;
    const auto counts = [&](int length) {
        return (only_length < 0 || only_length == length) && !(length == 0 && rules.hides_emitters());
    };
    Colour beta(1.0f);
    // `bounces`: the bounces made before the vertex at `hit`. At the depth limit a path under
    // --null-depth skip may still pass straight through surfaces (kLobeNull), and nothing else.
    for (int bounces = first_bounce, step = 0; step < kMaxBounces; ++step) {
        const bool may_scatter = rules.may_bounce(bounces);
        if (!may_scatter && !rules.skips_null()) break;
        const ShadingPoint sp = make_shading_point(scene, hit, dir);
        if (!may_scatter && !(sp.material->lobes() & kLobeNull)) break;
        if (sp.material->is_black()) break;
        // Paths of bounces + 1 bounces ending on a light: the MIS pair.
        if (may_scatter) {
            const Colour direct = estimate_light_sample(scene, sp, sampler, /*mis=*/true, wl, rules.power_mis(), BsdfStrategyPdf{},
                                                        static_cast<LightSampleSeen<Wl>*>(nullptr), /*split=*/bounces == 0);
            if (counts(bounces + 1)) L += beta * direct;
        }
        const auto s = bsdf_sample(sp, sampler.next2d(), wl);
        EmitterHit found;
        Colour f(0.0f);  // the continuation's BSDF value
        if (s) {
            f = bsdf_sample_colour(sp, *s, wl);
            const Colour found_emission = estimate_bsdf_sample_mis(scene, sp, *s, f, found, wl, rules.power_mis(), /*split=*/bounces == 0);
            const bool bounce = rules.is_bounce(s->lobe);
            if ((may_scatter || !bounce) && counts(bounces + (bounce ? 1 : 0))) L += beta * found_emission;
        }
        if (!rules.skips_null() && !rules.may_bounce(bounces + 1)) break;

        // Continue the path: with the same BSDF sample (pt-mis) or a fresh one (pt-mis3).
        // The fresh one is independent of the first: a rejected MIS sample (a direction
        // below the surface, total internal reflection on a microfacet) must not end it.
        if (!three_rays && !s) break;
        BsdfSample next = s ? *s : BsdfSample{};
        if (three_rays) {
            const auto c = bsdf_sample(sp, sampler.next2d(), wl);
            if (!c) break;
            next = *c;
            f = bsdf_sample_colour(sp, next, wl);
            found.hit = scene.intersect(sp.spawn(next.wo), found.isect);
        }
        const bool bounce = rules.is_bounce(next.lobe);
        if (!may_scatter && bounce) break;  // a scattering past the depth limit
        if (!found.hit) break;  // escaped: the environment was counted by the MIS pair
        beta *= f * (std::abs(next.wo.z) / next.pdfW);
        if (bounce && !rules.survive_roulette(bounces + 1, beta, sampler)) break;
        bounces += bounce ? 1 : 0;
        hit = found.isect;
        dir = sp.frame.to_world(next.wo);
    }
    return L;
}

template Rgb pt_mis_from_hit(const Scene&, Intersection, Vec3f, int, Sampler&, const PathRules&, RgbWavelengths&, bool, int, Rgb);
template Spectrum4 pt_mis_from_hit(const Scene&, Intersection, Vec3f, int, Sampler&, const PathRules&, SampledWavelengths&, bool, int,
                                   Spectrum4);

template <class Wl>
ColourAt<Wl> pt_mis_camera_radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, const PathRules& rules, Wl& wl,
                                    bool three_rays, int only_length) {
    using Colour = ColourAt<Wl>;
    const bool seen_directly = (only_length < 0 || only_length == 0) && !rules.hides_emitters();
    Intersection hit;
    if (!scene.intersect(camera_ray, hit)) return seen_directly ? escaped_radiance(scene, camera_ray.d, wl) : Colour(0.0f);
    const Colour emitted = seen_directly ? emitted_radiance(scene, hit, -camera_ray.d, wl) : Colour(0.0f);
    return pt_mis_from_hit(scene, hit, camera_ray.d, 0, sampler, rules, wl, three_rays, only_length, emitted);
}

template Rgb pt_mis_camera_radiance(const Scene&, const Ray&, Sampler&, const PathRules&, RgbWavelengths&, bool, int);
template Spectrum4 pt_mis_camera_radiance(const Scene&, const Ray&, Sampler&, const PathRules&, SampledWavelengths&, bool, int);

namespace {

IntegratorInfo skipping_null_events(IntegratorInfo info) {
    info.skips_null_events = true;
    return info;
}

template <class T>
class PtMis final : public PixelIntegrator<T> {
public:
    PtMis(const IntegratorOptions& o, bool separate_continuation)
        : rules_(limited_to_length(o)), three_rays_(separate_continuation), only_length_(o.only_length) {}

    ColourOf<T> radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, WavelengthsOf<T>& wl) const override {
        return pt_mis_camera_radiance(scene, camera_ray, sampler, rules_, wl, three_rays_, only_length_);
    }

private:
    PathRules rules_;
    bool three_rays_;
    int only_length_;
};

}  // namespace

const IntegratorInfo& pt_mis3_integrator() {
    static const IntegratorInfo info = skipping_null_events(sampling_lights(IntegratorInfo{"pt-mis3", {"4b"}, "path tracing, MIS direct lighting at every bounce + a third continuation ray",
                                     false, true, path_params(), [](const IntegratorOptions& o) { return make_for_transport<PtMis>(o, true); }}));
    return info;
}
const IntegratorInfo& pt_mis_integrator() {
    static const IntegratorInfo info = skipping_null_events(sampling_lights(IntegratorInfo{"pt-mis", {"4c", "path"}, "path tracing, MIS direct lighting whose BRDF ray continues the path",
                                     false, true, path_params(), [](const IntegratorOptions& o) { return make_for_transport<PtMis>(o, false); }}));
    return info;
}

}  // namespace pathlab
