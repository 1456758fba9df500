// pt-mis and pt-mis3 in spectral mode (docs/spectral.md, phase 2).
#include "integrators/path/pt_mis_spectral.hpp"

#include "integrators/common/spectral_direct_lighting.hpp"

namespace pathlab {

Spectrum4 pt_mis_spectral_from_hit(const Scene& scene, Intersection hit, Vec3f dir, int first_bounce, Sampler& sampler,
                                   const PathRules& rules, bool three_rays, int only_length, Spectrum4 L, SampledWavelengths& wl) {
    const auto counts = [only_length](int length) { return only_length < 0 || only_length == length; };
    Spectrum4 beta(1.0f);
    for (int bounces = first_bounce; rules.may_bounce(bounces); ++bounces) {
        const ShadingPoint sp = make_shading_point(scene, hit, dir);
        if (sp.material->is_black()) break;
        const Spectrum4 direct = estimate_light_sample_spectral(scene, sp, sampler, /*mis=*/true, wl);
        if (counts(bounces + 1)) L += beta * direct;
        const auto s = spectral_sample(sp, sampler.next2d(), wl);
        EmitterHit found;
        Spectrum4 f(0.0f);
        if (s) {
            f = spectral_sample_value(sp, *s, wl);
            const Spectrum4 found_emission = estimate_bsdf_sample_mis_spectral(scene, sp, *s, f, found, wl);
            if (counts(bounces + 1)) L += beta * found_emission;
        }
        if (!rules.may_bounce(bounces + 1)) break;
        if (!three_rays && !s) break;
        BsdfSample next = s ? *s : BsdfSample{};
        if (three_rays) {
            const auto c = spectral_sample(sp, sampler.next2d(), wl);
            if (!c) break;
            next = *c;
            f = spectral_sample_value(sp, next, wl);
            found.hit = scene.intersect(sp.spawn(next.wo), found.isect);
        }
        if (!found.hit) break;
        beta *= f * (std::abs(next.wo.z) / next.pdfW);
        if (!rules.survive_roulette(bounces + 1, beta, sampler)) break;
        hit = found.isect;
        dir = sp.frame.to_world(next.wo);
    }
    return L;
}

}  // namespace pathlab
