// All direct-illumination estimators converge to the same image: per-pixel z-tests of each
// against direct-mis (core/image_statistics.hpp), at a known false-alarm rate.
#include <gtest/gtest.h>

#include "judge/image_statistics.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

// Small images with many samples per pixel, so each pixel's mean is close to normal even for
// the heavy-tailed estimators (uniform hemisphere sampling of a cos^600 lobe).
constexpr int kSize = 16;
constexpr int kSpp = 16384;
// Each comparison raises a false alarm with probability <= 1e-4; with 26 comparisons the
// suite's false-alarm rate stays below 0.3%.
const AgreementOptions kAgreement{1e-3, 1e-4};

RenderResult render_small(int scene, const std::string& algorithm, uint64_t seed) {
    return render_scene(make_builtin_scene(scene), algorithm, kSize, kSize, kSpp, seed);
}

void expect_agreement(int scene, const std::vector<std::string>& algorithms) {
    const RenderResult mis = render_small(scene, "direct-mis", 202);
    for (const std::string& algorithm : algorithms) {
        const RenderResult a = render_small(scene, algorithm, 101);
        const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), mis.film.mean(),
                                                 mis.film.standard_error(), kAgreement);
        ::testing::Test::RecordProperty(algorithm, r.describe());
        EXPECT_TRUE(r.agree) << "scene " << scene << ", " << algorithm << " vs direct-mis: " << r.describe();
    }
}

class DirectAgreement : public ::testing::TestWithParam<int> {};

TEST_P(DirectAgreement, EveryDirectEstimatorConvergesToTheMisImage) {
    expect_agreement(GetParam(), {"direct-light", "direct-uniform", "direct-cosine", "direct-brdf"});
}
INSTANTIATE_TEST_SUITE_P(AreaAndEnvironmentScenes, DirectAgreement, ::testing::Range(2, 8));

TEST(DirectAgreement, LightSamplingConvergesToTheMisImageWithPointLights) {
    expect_agreement(0, {"direct-light"});
    expect_agreement(1, {"direct-light"});
}

// Test of the test: direct-brdf with the classic bug of dividing by the chosen lobe's density
// (times its selection probability) instead of the mixture density must disagree.
class BrdfSamplingWithChosenLobePdf final : public PixelIntegrator<RgbTransport> {
public:
    Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler, RgbWavelengths&) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return scene.escaped_radiance();
        const Rgb L = emitted_radiance(scene, hit, -ray.d);
        const ShadingPoint sp = make_shading_point(scene, hit, ray.d);
        if (sp.material->is_black()) return L;
        const auto& m = std::get<PhongMaterial>(sp.material->model);
        const float pd = m.diffuse_probability();
        Vec2f u = sampler.next2d();
        Vec3f wo;
        float pdf;
        if (u.x < pd) {
            u.x /= pd;
            wo = square_to_cosine_hemisphere(u);
            pdf = pd * cosine_hemisphere_pdf(wo);
        } else {
            u.x = (u.x - pd) / (1 - pd);
            wo = Frame(PhongMaterial::mirror(sp.wi)).to_world(square_to_power_cosine(u, m.exponent));
            pdf = (1 - pd) * power_cosine_pdf(dot(PhongMaterial::mirror(sp.wi), wo), m.exponent);
        }
        if (wo.z <= 0 || !(pdf > 0)) return L;
        const EmitterHit e = trace_to_emitter(scene, sp.spawn(wo), sp.p, sp.frame.n);
        return L + m.eval(sp.wi, wo) * e.Le * (wo.z / pdf);
    }
};

TEST(DirectAgreement, DetectsTheChosenLobePdfBug) {
    const auto scene = Scene::build(make_builtin_scene(3));
    RenderSettings rs;
    rs.width = rs.height = kSize;
    rs.spp = kSpp;
    rs.seed = 101;
    const RenderResult bad = render(*scene, BrdfSamplingWithChosenLobePdf(), rs);
    const RenderResult mis = render_small(3, "direct-mis", 202);
    const AgreementResult r =
        test_agreement(bad.film.mean(), bad.film.standard_error(), mis.film.mean(), mis.film.standard_error(), kAgreement);
    EXPECT_FALSE(r.agree) << r.describe();
}

// Point lights cannot be hit by sampled directions: 2a-2c see nothing but direct emission,
// and the course's point-light scenes have none.
TEST(DirectAgreement, DirectionSamplingIsBlackWithOnlyAPointLight) {
    for (int scene : {0, 1})
        for (const char* a : {"direct-uniform", "direct-cosine", "direct-brdf"}) {
            const Image img = render_scene(make_builtin_scene(scene), a, 16, 16, 4).film.mean();
            for (size_t i = 0; i < img.pixel_count(); ++i) ASSERT_EQ(img[i], Rgb(0.0f)) << a << " scene " << scene;
        }
}

}  // namespace
}  // namespace pathlab::test
