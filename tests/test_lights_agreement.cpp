// The new lights seen by the bidirectional estimators: bdpt and the light tracer converge to
// pt-mis's image (per-pixel z-tests, as tests/test_bdpt.cpp and test_light_tracer.cpp judge
// them) on an outdoor scene lit by an environment map with a sun, and on the course's diffuse
// box lit by a spot and an IES light instead of its point light; and the direct-illumination
// estimators agree with each other under the map. Each comparison raises a false alarm with
// probability <= 1e-4.
#include <gtest/gtest.h>

#include "integrators/bidir/bdpt.hpp"
#include "integrators/bidir/light_tracer.hpp"
#include "judge/image_statistics.hpp"
#include "judge/specular_mask.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

const AgreementOptions kAgreement{1e-3, 1e-4};

// A diffuse floor, a diffuse and a glossy ball under a sky map (brighter overhead, a dim ground
// and a sun of about 30 texels 100 times brighter), the map's +y turned to the scene's +z.
SceneDescription envmap_scene() {
    SceneDescription d;
    d.name = "envmap-balls";
    d.camera = Camera::look_along({0, -4, 1.6f}, normalize(Vec3f(0, 4, -1.2f)), {0, 0, 1}, 40.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(0.6f)), make_phong(Rgb(0.7f, 0.6f, 0.5f)), make_phong(Rgb(0.2f, 0.3f, 0.5f), Rgb(0.5f), 30)};
    MeshDesc floor;
    floor.positions = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
    floor.triangles = {{0, 1, 2}, {2, 3, 0}};
    d.meshes.push_back(floor);
    d.spheres.push_back(SphereDesc{{-0.6f, 0, 0.5f}, 0.5f, 1});
    d.spheres.push_back(SphereDesc{{0.6f, 0.3f, 0.5f}, 0.5f, 2});
    const int w = 32, h = 16;
    const Vec3f sun = normalize(Vec3f(0.5f, 0.6f, -0.4f));  // in the map's frame (+y up)
    std::vector<Rgb> texels;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Vec3f dir = EnvMap::uv_to_direction({(x + 0.5f) / w, (y + 0.5f) / h});
            if (dot(dir, sun) > std::cos(12 * kPi / 180)) texels.push_back(Rgb(60, 55, 50));
            else texels.push_back(dir.y > 0 ? Rgb(0.3f, 0.45f, 0.8f) * (0.5f + dir.y) : Rgb(0.15f, 0.12f, 0.1f));
        }
    Frame up_is_z;
    up_is_z.s = {1, 0, 0}, up_is_z.t = {0, 0, 1}, up_is_z.n = {0, -1, 0};
    d.lights.emplace_back(EnvMapLight{std::make_shared<const EnvMap>(w, h, std::move(texels), up_is_z)});
    return d;
}

// Course scene 0 with a spot on the floor and an asymmetric IES light on the ceiling instead of
// its point light.
SceneDescription spot_ies_scene() {
    SceneDescription d = make_builtin_scene(0);
    d.lights.clear();
    d.lights.emplace_back(SpotLight({-0.2f, -0.6f, 1.1f}, normalize(Vec3f(0.1f, 0.5f, -1)), Rgb(6, 5, 4), 40, 15));
    Frame down;
    down.s = {0, 1, 0}, down.t = {1, 0, 0}, down.n = {0, 0, -1};
    d.lights.emplace_back(IesLight{{0.3f, 0.2f, 1.2f}, down, Rgb(2.0f) / kLumensPerWatt,
                                   std::make_shared<const IesDistribution>(read_ies_file(std::string(PATHLAB_SOURCE_DIR) +
                                                                                         "/tests/data/ies/asymmetric-full.ies"))});
    return d;
}

AgreementResult agree(const RenderResult& a, const RenderResult& b, const std::vector<uint8_t>* excluded = nullptr) {
    AgreementOptions o = kAgreement;
    o.excluded = excluded;
    return test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), o);
}

struct Case {
    const char* name;
    SceneDescription (*scene)();
    int w, h;
    uint64_t spp;
};
const Case kCases[] = {{"envmap", envmap_scene, 12, 9, 8192}, {"spot_ies", spot_ies_scene, 8, 8, 8192}};

class NewLightsAgreement : public ::testing::TestWithParam<Case> {};

TEST_P(NewLightsAgreement, BdptAndLightTracingConvergeToPtMis) {
    const Case& c = GetParam();
    const SceneDescription d = c.scene();
    const RenderResult pt = render_scene(d, "pt-mis", c.w, c.h, int(c.spp), 501);
    Bdpt<RgbTransport> bdpt({});
    const AgreementResult b = agree(render_integrator(d, bdpt, c.w, c.h, c.spp, 502), pt);
    RecordProperty("bdpt", b.describe());
    EXPECT_TRUE(b.agree) << c.name << ", bdpt: " << b.describe();
    LightTracer<RgbTransport> lt({});
    const auto scene = Scene::build(d);
    const std::vector<uint8_t> mask = specular_first_vertex_mask(*scene, c.w, c.h, 16, /*dilate=*/false);
    const AgreementResult l = agree(render_integrator(d, lt, c.w, c.h, 2 * c.spp, 503), pt, &mask);
    RecordProperty("lt", l.describe());
    EXPECT_TRUE(l.agree) << c.name << ", lt: " << l.describe();
}

// The direct-illumination estimators under the map: light sampling, BSDF sampling and their
// MIS combination converge to one image (the map's lookup, its pdf_li in the MIS weights and its
// sampling all enter).
TEST(NewLightsAgreement, DirectEstimatorsAgreeUnderAnEnvmap) {
    const SceneDescription d = envmap_scene();
    const RenderResult mis = render_scene(d, "direct-mis", 12, 9, 4096, 601);
    for (const char* other : {"direct-light", "direct-brdf"}) {
        const AgreementResult r = agree(render_scene(d, other, 12, 9, 4096, 602), mis);
        RecordProperty(other, r.describe());
        EXPECT_TRUE(r.agree) << other << ": " << r.describe();
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, NewLightsAgreement, ::testing::ValuesIn(kCases), [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace pathlab::test
