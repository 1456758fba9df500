// direct-light against closed forms: a point light over a diffuse plane, and emitters seen
// directly by the camera.
#include <gtest/gtest.h>

#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

constexpr float kRho = 0.5f, kIntensity = 2.0f;
const Vec3f kLight(0.3f, -0.2f, 1.5f);

SceneDescription point_light_over_plane(float intensity = kIntensity) {
    SceneDescription d;
    d.name = "plane";
    d.width = d.height = 32;
    d.camera = Camera::look_along({0.1f, 0.0f, 3.0f}, {0, 0, -1}, {0, 1, 0}, 60.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(kRho))};
    MeshDesc plane;
    plane.positions = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}};
    plane.triangles = {{0, 1, 2}, {2, 3, 0}};
    d.meshes.push_back(plane);
    d.lights.emplace_back(PointLight{kLight, Rgb(intensity)});
    return d;
}

// Outgoing radiance of the plane at x: rho/pi * I cos(theta) / d^2.
double closed_form(double x, double y) {
    const double dx = kLight.x - x, dy = kLight.y - y, dz = kLight.z;
    const double d2 = dx * dx + dy * dy + dz * dz;
    return kRho / M_PI * kIntensity * (dz / std::sqrt(d2)) / d2;
}

// Where a camera ray through raster point (sx, sy) meets the plane z = 0.
std::pair<double, double> plane_hit(const PerspectiveCamera& cam, float sx, float sy) {
    const Ray r = cam.generate(sx, sy);
    const double t = -double(r.o.z) / double(r.d.z);
    return {r.o.x + t * r.d.x, r.o.y + t * r.d.y};
}

TEST(PointLightOverPlane, EveryPixelCentreMatchesTheClosedForm) {
    const auto scene = Scene::build(point_light_over_plane());
    const auto estimator = make_pixel_integrator("direct-light");
    RgbWavelengths rgb;
    const PerspectiveCamera cam(scene->camera(), 32, 32);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            Sampler sampler(1, uint64_t(y * 32 + x), 0);
            const Rgb L = estimator->radiance(*scene, cam.generate(x + 0.5f, y + 0.5f), sampler, rgb);
            const auto [px, py] = plane_hit(cam, x + 0.5f, y + 0.5f);
            const double expected = closed_form(px, py);
            ASSERT_NEAR(L.x, expected, 1e-5 * expected) << "pixel " << x << "," << y;
            ASSERT_EQ(L.x, L.y);
            ASSERT_EQ(L.x, L.z);
        }
}

// The rendered image (jittered samples over each pixel) against the closed form averaged over
// the pixel footprint, judged by the per-pixel standard errors.
AgreementResult render_against_closed_form(float intensity) {
    const RenderResult r = render_scene(point_light_over_plane(intensity), "direct-light", 32, 32, 64, 7);
    const PerspectiveCamera cam(Camera(Scene::build(point_light_over_plane())->camera()), 32, 32);
    Image exact(32, 32);
    constexpr int kSub = 32;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            double sum = 0;
            for (int j = 0; j < kSub; ++j)
                for (int i = 0; i < kSub; ++i) {
                    const auto [px, py] = plane_hit(cam, x + (i + 0.5f) / kSub, y + (j + 0.5f) / kSub);
                    sum += closed_form(px, py);
                }
            exact.at(x, y) = Rgb(float(sum / (kSub * kSub)));
        }
    return test_agreement(r.film.mean(), r.film.standard_error(), exact, Image());
}

TEST(PointLightOverPlane, RenderAgreesWithThePixelAveragedClosedForm) {
    const AgreementResult a = render_against_closed_form(kIntensity);
    RecordProperty("agreement", a.describe());
    EXPECT_TRUE(a.agree) << a.describe();
}

TEST(PointLightOverPlane, OnePercentTooBrightIsDetected) {
    const AgreementResult a = render_against_closed_form(kIntensity * 1.01f);
    RecordProperty("agreement", a.describe());
    EXPECT_FALSE(a.agree) << a.describe();
}

// Camera rays that hit an emitter return exactly its radiance (emitters reflect nothing).
void expect_emitter_pixels_exact(int scene_index, float radiance, int min_pixels) {
    const auto scene = Scene::build(make_builtin_scene(scene_index));
    const auto estimator = make_pixel_integrator("direct-light");
    RgbWavelengths rgb;
    const PerspectiveCamera cam(scene->camera(), 512, 512);
    int seen = 0;
    for (int y = 0; y < 512; y += 2)
        for (int x = 0; x < 512; x += 2) {
            const Ray ray = cam.generate(x + 0.5f, y + 0.5f);
            Intersection hit;
            if (!scene->intersect(ray, hit) || hit.light < 0) continue;
            Sampler sampler(3, uint64_t(y * 512 + x), 0);
            const Rgb L = estimator->radiance(*scene, ray, sampler, rgb);
            ASSERT_EQ(L, Rgb(radiance)) << "pixel " << x << "," << y;
            ++seen;
        }
    EXPECT_GE(seen, min_pixels);
}

TEST(AreaLight, PerspectiveCameraHittingTheCeilingReturnItsRadiance) { expect_emitter_pixels_exact(2, 1.21f, 41'618 / 4 - 200); }
TEST(AreaLight, PerspectiveCameraHittingTheLightBoxReturnItsRadiance) { expect_emitter_pixels_exact(4, 31.831f, 1'518 / 4 - 50); }

TEST(AreaLight, EmitsOnItsNormalSideOnly) {
    const TriangleLight tri({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, Rgb(2.0f));  // normal +z
    EXPECT_EQ(tri.radiance_at({0.3f, 0.3f}), Rgb(2.0f));
    EXPECT_GT(tri.pdf_emission({0.2f, 0.2f, 0}, tri.normal, {0, 0, 1}, {}).pdfW, 0.0f);
    EXPECT_EQ(tri.pdf_emission({0.2f, 0.2f, 0}, tri.normal, normalize(Vec3f(1, 1, -1)), {}).pdfW, 0.0f);
    EXPECT_FALSE(tri.sample_li({0.2f, 0.2f, -1.0f}, {0.3f, 0.3f}));  // behind it: nothing to sample
    EXPECT_TRUE(tri.sample_li({0.2f, 0.2f, 1.0f}, {0.3f, 0.3f}));
}

TEST(Environment, EscapingRaysReturnItsRadiance) {
    SceneDescription d = point_light_over_plane();
    d.lights = {EnvironmentLight{Rgb(0.25f, 0.5f, 0.75f)}};
    const auto scene = Scene::build(d);
    const auto estimator = make_pixel_integrator("direct-light");
    RgbWavelengths rgb;
    Sampler sampler(1, 0, 0);
    EXPECT_EQ(estimator->radiance(*scene, Ray{{0, 0, 1}, {0, 0, 1}, kInf}, sampler, rgb), Rgb(0.25f, 0.5f, 0.75f));
}

}  // namespace
}  // namespace pathlab::test
