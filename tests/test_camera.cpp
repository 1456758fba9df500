// Camera importance: We integrates to 1 over the image's directions, connect() projects a
// point to the pixel that traces back to it, and the directions of generate() follow
// pdf_direction() (chi-square), for the course's camera (each axis spans the field of view,
// non-square pixels) and a square-pixel camera.
#include <gtest/gtest.h>

#include <cmath>

#include "cameras/camera.hpp"
#include "chi2.hpp"
#include "core/sampling.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::test {
namespace {

struct CameraCase {
    const char* name;
    Camera camera;
    int width, height;
};

std::vector<CameraCase> cameras() {
    const Camera course = make_builtin_scene(0).camera;
    return {{"course_64x48", course, 64, 48},
            {"square_pixels_40x90",
             Camera::look_at({1, -3, 0.5f}, {0, 0, 0.2f}, {0, 0, 1}, 50.0f, FovAxis::X), 40, 90}};
}

void PrintTo(const CameraCase& c, std::ostream* os) { *os << c.name; }

class CameraImportance : public ::testing::TestWithParam<CameraCase> {};

TEST_P(CameraImportance, WeIntegratesToOneOverTheImage) {
    const CameraCase& c = GetParam();
    const PerspectiveCamera cam(c.camera, c.width, c.height);
    // Monte Carlo over uniformly distributed directions: E[We cos theta / pdf] = 1.
    Sampler rng(11, 0, 0);
    const int n = 2'000'000;
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3f d = square_to_uniform_sphere(rng.next2d());
        const double v = double(cam.We(d)) * std::max(0.0f, dot(d, cam.forward())) / uniform_sphere_pdf();
        sum += v, sum2 += v * v;
    }
    const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
    EXPECT_NEAR(mean, 1.0, 4.5 * se) << "standard error " << se;  // 4.5 sigma: false alarm 7e-6
}

TEST_P(CameraImportance, AProjectedPointTracesBackToItsPixel) {
    const CameraCase& c = GetParam();
    const PerspectiveCamera cam(c.camera, c.width, c.height);
    Sampler rng(12, 0, 0);
    int inside = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f p = cam.position() + square_to_uniform_sphere(rng.next2d()) * (0.5f + 4 * rng.next1d());
        const auto k = cam.connect(p);
        const Vec3f towards_p = normalize(p - cam.position());
        if (!k) {
            EXPECT_EQ(cam.We(towards_p), 0.0f);
            continue;
        }
        ++inside;
        EXPECT_NEAR(length(p + k->wi * k->distance - cam.position()), 0.0f, 1e-5f);
        const Ray r = cam.generate(k->raster.x, k->raster.y);
        EXPECT_GT(dot(r.d, towards_p), 1 - 1e-6f);
        // The pixel of the raster position is the pixel whose area the traced ray crosses.
        const size_t pixel = cam.pixel_of(k->raster);
        EXPECT_EQ(pixel, size_t(int(k->raster.y)) * size_t(c.width) + size_t(int(k->raster.x)));
        EXPECT_FLOAT_EQ(k->We, cam.We(-k->wi));
        const float cos_lens = dot(-k->wi, cam.forward());
        EXPECT_FLOAT_EQ(k->pdfW, k->distance * k->distance / cos_lens);
    }
    EXPECT_GT(inside, 500);
}

TEST_P(CameraImportance, GeneratedDirectionsFollowPdfDirection) {
    const CameraCase& c = GetParam();
    const PerspectiveCamera cam(c.camera, c.width, c.height);
    Chi2Options opt;
    opt.theta_power = 1.5;
    opt.integration_steps = 48;  // the image's rectangular border cuts cells
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> { return cam.generate(u.x * float(c.width), u.y * float(c.height)).d; },
        [&](const Vec3f& w) { return cam.pdf_direction(w); }, cam.forward(), opt);
    EXPECT_GT(r.p_value, suite_chi2_alpha()) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.describe();
}

INSTANTIATE_TEST_SUITE_P(Cameras, CameraImportance, ::testing::ValuesIn(cameras()),
                         [](const auto& info) { return std::string(info.param.name); });

// Test of the test: leaving the receiving cosine out of the integral misses 1 by many
// standard errors.
TEST(CameraImportance, DetectsAMissingCosine) {
    const PerspectiveCamera cam(make_builtin_scene(0).camera, 64, 64);
    Sampler rng(11, 0, 0);
    const int n = 2'000'000;
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3f d = square_to_uniform_sphere(rng.next2d());
        const double v = double(cam.We(d)) / uniform_sphere_pdf();  // the receiving cosine left out
        sum += v, sum2 += v * v;
    }
    const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
    EXPECT_GT(std::abs(mean - 1.0), 10 * se) << mean;
}

}  // namespace
}  // namespace pathlab::test
