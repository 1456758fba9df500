// The path tracers (and bdpt): furnace scenes with closed-form answers, equivalence with direct-mis
// at one bounce, agreement with each other, and unbiased Russian roulette.
#include <gtest/gtest.h>

#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

const AgreementOptions kAgreement{1e-3, 1e-4};
constexpr int kGlobalSpp = 8192;
const std::vector<std::string> kPathTracers = {"pt-naive", "pt-mis3", "pt-mis", "bdpt"};

// A closed cube seen from inside: every wall emits Le (towards the inside) and reflects
// diffusely with albedo rho. Radiance is the same everywhere: L = Le + rho L, so
// L = Le / (1 - rho).
SceneDescription emitting_enclosure(float Le, float rho) {
    SceneDescription d;
    d.name = "enclosure";
    d.camera = Camera::look_along({0.2f, -0.5f, 0.1f}, {0.3f, 1.0f, 0.2f}, {0, 0, 1}, 70.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(rho))};
    MeshDesc box;
    box.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
    // Windings with normals pointing into the cube.
    box.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}, {0, 4, 5}, {0, 5, 1},
                     {1, 5, 6}, {1, 6, 2}, {2, 6, 7}, {2, 7, 3}, {3, 7, 4}, {3, 4, 0}};
    box.emission = Rgb(Le);
    d.meshes.push_back(box);
    return d;
}

// The course's box (open at the front) with two spheres, everything white diffuse with albedo
// 1, in a constant environment: no energy is lost, so every pixel sees L = Le.
SceneDescription white_furnace(Rgb Le) {
    SceneDescription d = make_builtin_scene(6);
    for (Material& m : d.materials) m = make_phong(Rgb(1.0f));
    d.lights = {EnvironmentLight{Le}};
    return d;
}

AgreementResult against_constant(const RenderResult& r, Rgb expected) {
    return test_agreement(r.film.mean(), r.film.standard_error(), Image(r.film.width(), r.film.height(), expected), Image(),
                          kAgreement);
}

class Furnace : public ::testing::TestWithParam<std::string> {};

TEST_P(Furnace, EmittingEnclosureGivesLeOverOneMinusRho) {
    const float Le = 0.5f, rho = 0.6f;
    const RenderResult r = render_scene(emitting_enclosure(Le, rho), GetParam(), 8, 8, 4096, 3);
    const AgreementResult a = against_constant(r, Rgb(Le / (1 - rho)));
    EXPECT_TRUE(a.agree) << a.describe();
}

TEST_P(Furnace, WhiteObjectsInAConstantEnvironmentGiveLe) {
    const Rgb Le(0.3f, 0.6f, 0.9f);
    const RenderResult r = render_scene(white_furnace(Le), GetParam(), 8, 8, 2048, 4);
    const AgreementResult a = against_constant(r, Le);
    EXPECT_TRUE(a.agree) << a.describe();
}

TEST_P(Furnace, AWrongAnswerIsDetected) {
    // Test of the test: the same renders against an answer 1% off must disagree.
    const float Le = 0.5f, rho = 0.6f;
    const RenderResult r = render_scene(emitting_enclosure(Le, rho), GetParam(), 8, 8, 4096, 3);
    EXPECT_FALSE(against_constant(r, Rgb(1.01f * Le / (1 - rho))).agree);
}
INSTANTIATE_TEST_SUITE_P(PathTracers, Furnace, ::testing::ValuesIn(kPathTracers), [](const auto& info) {
    std::string n = info.param;
    std::replace(n.begin(), n.end(), '-', '_');
    return n;
});

IntegratorOptions depth(int max_depth, int rr_depth = 3) {
    IntegratorOptions o;
    o.max_depth = max_depth;
    o.rr_depth = rr_depth;
    return o;
}

AgreementResult compare(const RenderResult& a, const RenderResult& b) {
    return test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), kAgreement);
}

// With one bounce, the MIS path tracers are direct-mis.
TEST(PathTracing, OneBounceOfTheMisPathTracersIsDirectMis) {
    for (int scene : {1, 3, 4, 7}) {
        const RenderResult ref = render_scene(make_builtin_scene(scene), "direct-mis", 16, 16, 4096, 11);
        for (const char* a : {"pt-mis3", "pt-mis"}) {
            const AgreementResult r = compare(render_scene(make_builtin_scene(scene), a, 16, 16, 4096, 12, depth(1)), ref);
            EXPECT_TRUE(r.agree) << "scene " << scene << " " << a << ": " << r.describe();
        }
    }
}

// The three path tracers converge to one global-illumination image (pt-naive cannot see the
// point light, so only the MIS ones are compared in scenes 0 and 1).
class GlobalAgreement : public ::testing::TestWithParam<int> {};

TEST_P(GlobalAgreement, PathTracersConvergeToTheSameImage) {
    const int scene = GetParam();
    const bool point_light = scene < 2;
    const RenderResult ref = render_scene(make_builtin_scene(scene), "pt-mis", 16, 16, kGlobalSpp, 21);
    for (const char* a : {"pt-naive", "pt-mis3"}) {
        if (point_light && std::string(a) == "pt-naive") continue;
        const AgreementResult r = compare(render_scene(make_builtin_scene(scene), a, 16, 16, kGlobalSpp, 22), ref);
        ::testing::Test::RecordProperty(a, r.describe());
        EXPECT_TRUE(r.agree) << "scene " << scene << " " << a << " vs pt-mis: " << r.describe();
    }
}
INSTANTIATE_TEST_SUITE_P(Scenes, GlobalAgreement, ::testing::Range(0, 8));

// --mis power weighs the light and BSDF samples of pt-mis, pt-mis3 and direct-mis by the power
// heuristic: another estimator of the same image (the glossy ceiling, the glossy spheres under
// the light box), not the balance heuristic's bytes.
TEST(PathTracing, ThePowerHeuristicConvergesToTheBalanceHeuristicsImage) {
    IntegratorOptions power;
    power.mis_power = true;
    for (int scene : {2, 5}) {
        const RenderResult ref = render_scene(make_builtin_scene(scene), "pt-mis", 16, 16, 4096, 41);
        for (const char* a : {"pt-mis", "pt-mis3"}) {
            const RenderResult p = render_scene(make_builtin_scene(scene), a, 16, 16, 4096, 42, power);
            const AgreementResult r = compare(p, ref);
            EXPECT_TRUE(r.agree) << "scene " << scene << " " << a << ": " << r.describe();
        }
        const RenderResult balance = render_scene(make_builtin_scene(scene), "direct-mis", 16, 16, 4096, 43);
        const RenderResult p = render_scene(make_builtin_scene(scene), "direct-mis", 16, 16, 4096, 43, power);
        EXPECT_FALSE(bit_identical(p.film.mean(), balance.film.mean())) << "scene " << scene;
        const AgreementResult r = compare(p, render_scene(make_builtin_scene(scene), "direct-mis", 16, 16, 4096, 44));
        EXPECT_TRUE(r.agree) << "scene " << scene << " direct-mis: " << r.describe();
    }
}

TEST(PathTracing, NaiveIsBlackWithOnlyAPointLight) {
    const Image img = render_scene(make_builtin_scene(0), "pt-naive", 16, 16, 16).film.mean();
    for (size_t i = 0; i < img.pixel_count(); ++i) ASSERT_EQ(img[i], Rgb(0.0f));
}

// Russian roulette only trades variance for speed: with a depth cap, roulette from the first
// bounce and no roulette at all agree.
TEST(PathTracing, RussianRouletteOnAndOffAgree) {
    for (const std::string& a : kPathTracers) {
        const RenderResult on = render_scene(make_builtin_scene(3), a, 16, 16, 4096, 31, depth(6, 0));
        const RenderResult off = render_scene(make_builtin_scene(3), a, 16, 16, 4096, 32, depth(6, -1));
        const AgreementResult r = compare(on, off);
        EXPECT_TRUE(r.agree) << a << ": " << r.describe();
    }
}

TEST(PathTracing, MaxDepthLimitsTheLight) {
    // More bounces can only add light (all terms are non-negative), and the sum converges.
    const auto mean_of = [](const RenderResult& r) {
        double s = 0;
        const Image m = r.film.mean();
        for (size_t i = 0; i < m.pixel_count(); ++i) s += m[i].y;
        return s / double(m.pixel_count());
    };
    const double one = mean_of(render_scene(make_builtin_scene(2), "pt-mis", 16, 16, 256, 41, depth(1)));
    const double two = mean_of(render_scene(make_builtin_scene(2), "pt-mis", 16, 16, 256, 41, depth(2)));
    EXPECT_GT(two, one * 1.05);
}

}  // namespace
}  // namespace pathlab::test
