// Multiple importance sampling: both strategies evaluate the same two densities for the same
// direction, so the balance-heuristic weights of a path sum to one.
#include <gtest/gtest.h>

#include "integrators/common/direct_lighting.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

// From shading points seen by the camera, sample lights; for each sampled direction compute
// the light-sampling density twice (as light sampling reports it, and as the BSDF-sampled
// half finds it by tracing the direction) and check the two weights sum to 1.
void check_weights(int scene_index, LightSamplerKind lights = LightSamplerKind::Power) {
    SceneDescription d = make_builtin_scene(scene_index);
    d.light_sampler = lights;
    const auto scene = Scene::build(d);
    const PerspectiveCamera cam(scene->camera(), 64, 64);
    Sampler rng(21, 0, 0);
    int checked = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec2f px = rng.next2d();
        const Ray ray = cam.generate(px.x * 64, px.y * 64);
        Intersection hit;
        if (!scene->intersect(ray, hit)) continue;
        const ShadingPoint sp = make_shading_point(*scene, hit, ray.d);
        if (sp.material->is_black()) continue;
        const LightChoice choice = scene->choose_light(sp.p, sp.frame.n, rng.next1d());
        const auto ls = sample_light(scene->lights()[size_t(choice.index)], sp.p, rng.next2d());
        if (!ls || ls->delta || dot(ls->wi, sp.ng) <= 0) continue;
        const Ray probe = sp.spawn(sp.frame.to_local(ls->wi));
        const EmitterHit found = trace_to_emitter(*scene, probe, sp.p, sp.frame.n);
        if (is_black(found.Le)) continue;  // occluded: this direction finds another surface
        const float p_light = choice.pmf * ls->pdfW;
        ASSERT_NEAR(found.pdf_light, p_light, 1e-3f * p_light) << "scene " << scene_index << " sample " << i;
        const float p_brdf = sp.material->pdf(sp.wi, sp.frame.to_local(ls->wi));
        const float sum = balance_heuristic(p_light, p_brdf) + balance_heuristic(p_brdf, found.pdf_light);
        ASSERT_NEAR(sum, 1.0f, 1e-3f);
        ++checked;
    }
    EXPECT_GT(checked, 500) << "scene " << scene_index;
}

TEST(Mis, WeightsOfBothStrategiesSumToOneWithTheCeilingLight) { check_weights(3); }
TEST(Mis, WeightsOfBothStrategiesSumToOneWithTheLightBox) { check_weights(5); }
TEST(Mis, WeightsOfBothStrategiesSumToOneWithTheEnvironment) { check_weights(7); }
// The same with the light BVH, whose probabilities depend on the shading point and its normal.
TEST(Mis, WeightsSumToOneWithTheLightBvh) {
    check_weights(3, LightSamplerKind::Bvh);
    check_weights(5, LightSamplerKind::Bvh);
}

}  // namespace
}  // namespace pathlab::test
