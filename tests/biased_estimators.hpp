// Deliberately wrong estimators, for tests that must be able to fail.
#pragma once

#include <cmath>

#include "integrators/common/direct_lighting.hpp"
#include "integrators/integrator.hpp"

namespace pathlab::test {

// direct-light with the receiver's cos(theta) dropped (a classic student bug).
class DirectLightWithoutCosine final : public PixelIntegrator<RgbTransport> {
public:
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler, RgbWavelengths&) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return scene.escaped_radiance();
        const Rgb Le = emitted_radiance(scene, hit, -ray.d);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        const LightChoice choice = scene.choose_light(sp.p, sp.frame.n, sampler.next1d());
        const auto ls = sample_light(scene.lights()[size_t(choice.index)], sp.p, sampler.next2d());
        if (sp.material->is_black() || !ls || dot(ls->wi, sp.ng) <= 0) return Le;
        const Ray shadow = std::isinf(ls->distance) ? spawn_ray(sp.p, sp.ng, ls->wi)
                                                    : spawn_segment(sp.p, sp.ng, ls->point, ls->normal);
        if (scene.occluded(shadow)) return Le;
        return Le + sp.material->eval(sp.wi, sp.frame.to_local(ls->wi)) * ls->Le / (choice.pmf * ls->pdfW);
    }
};

}  // namespace pathlab::test
