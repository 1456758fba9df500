// Chi-square goodness-of-fit of the sampling warps and the light samplers against their pdfs.
#include <gtest/gtest.h>

#include "chi2.hpp"
#include "core/sampling.hpp"
#include "lights/light.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();

TEST(Chi2Harness, SurvivalFunctionMatchesKnownQuantiles) {
    EXPECT_NEAR(chi2_survival(3.841459, 1), 0.05, 1e-6);
    EXPECT_NEAR(chi2_survival(18.307038, 10), 0.05, 1e-6);
    EXPECT_NEAR(chi2_survival(124.342113, 100), 0.05, 1e-6);
    EXPECT_NEAR(chi2_survival(1.0, 2), std::exp(-0.5), 1e-12);
}

TEST(Sampling, UniformSphereMatchesPdf) {
    const auto r = chi2_directions([](Vec2f u) { return square_to_uniform_sphere(u); },
                                   [](const Vec3f&) { return uniform_sphere_pdf(); }, {0, 0, 1});
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
}

TEST(Sampling, UniformHemisphereMatchesPdf) {
    const auto r = chi2_directions([](Vec2f u) { return square_to_uniform_hemisphere(u); },
                                   [](const Vec3f& w) { return uniform_hemisphere_pdf(w); }, {0, 0, 1});
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

TEST(Sampling, CosineHemisphereMatchesPdf) {
    const auto r = chi2_directions([](Vec2f u) { return square_to_cosine_hemisphere(u); },
                                   [](const Vec3f& w) { return cosine_hemisphere_pdf(w); }, {0, 0, 1});
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
}

class PowerCosine : public ::testing::TestWithParam<float> {};

TEST_P(PowerCosine, MatchesPdf) {
    const float n = GetParam();
    Chi2Options opt;
    opt.theta_power = n > 10 ? 2.0 : 1;  // resolve narrow lobes near the axis
    const auto r = chi2_directions([n](Vec2f u) { return square_to_power_cosine(u, n); },
                                   [n](const Vec3f& w) { return power_cosine_pdf(w.z, n); }, {0, 0, 1}, opt);
    EXPECT_GT(r.p_value, kAlpha) << "n = " << n << ": " << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}
INSTANTIATE_TEST_SUITE_P(Exponents, PowerCosine, ::testing::Values(1.0f, 90.0f, 600.0f),
                         [](const auto& info) { return "n" + std::to_string(int(info.param)); });

// Tests of the tests. A lobe of the wrong shape (exponent 100 claimed for samples drawn with
// exponent 90) must fail the chi-square test; a wrong normalisation ((n+2)/(2pi), the BRDF's,
// instead of the sampler's (n+1)/(2pi)) must fail the integral check used above.
TEST(Chi2Harness, RejectsAPowerCosineLobeOfTheWrongShape) {
    Chi2Options opt;
    opt.theta_power = 2.0;
    const auto r = chi2_directions([](Vec2f u) { return square_to_power_cosine(u, 90.0f); },
                                   [](const Vec3f& w) { return power_cosine_pdf(w.z, 100.0f); }, {0, 0, 1}, opt);
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
}

TEST(Chi2Harness, DetectsAWronglyNormalisedPdf) {
    const float n = 90;
    Chi2Options opt;
    opt.theta_power = 2.0;
    const auto r = chi2_directions([n](Vec2f u) { return square_to_power_cosine(u, n); },
                                   [n](const Vec3f& w) { return power_cosine_pdf(w.z, n) * (n + 2) / (n + 1); },
                                   {0, 0, 1}, opt);
    EXPECT_GT(std::abs(r.pdf_integral - 1.0), 1e-3) << r.describe();
}

TEST(Chi2Harness, RejectsUniformSamplesClaimedCosine) {
    const auto r = chi2_directions([](Vec2f u) { return square_to_uniform_hemisphere(u); },
                                   [](const Vec3f& w) { return cosine_hemisphere_pdf(w); }, {0, 0, 1});
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
}

// Uniform triangle sampling, tested in barycentric coordinates on an n x n grid: the diagonal
// b1 + b2 = 1 cuts the diagonal cells exactly in half, so expected counts are exact.
TEST(Sampling, TrianglePointsAreUniformByArea) {
    const Vec3f a(0.3f, -1.0f, 2.0f), b(2.5f, 0.5f, 1.0f), c(-0.7f, 1.5f, 0.2f);
    const TriangleLight tri(a, b, c, Rgb(1.0f));
    const Vec3f ref(0.0f, 0.0f, 10.0f);
    const int n = 40, N = 1'000'000;
    std::vector<double> observed(size_t(n * n) + 1, 0.0), expected(observed.size(), 0.0);
    Sampler rng(7, 0, 0);
    // Solve q = a + b1 (b - a) + b2 (c - a) by least squares (q lies in the plane).
    const Vec3f e1 = b - a, e2 = c - a;
    const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), det = d11 * d22 - d12 * d12;
    for (int i = 0; i < N; ++i) {
        const auto s = tri.sample_li(ref, rng.next2d());
        if (!s) {
            observed.back() += 1;
            continue;
        }
        const Vec3f q = s->point - a;
        const float r1 = dot(q, e1), r2 = dot(q, e2);
        const float b1 = (d22 * r1 - d12 * r2) / det, b2 = (d11 * r2 - d12 * r1) / det;
        const int i1 = std::clamp(int(b1 * n), 0, n - 1), i2 = std::clamp(int(b2 * n), 0, n - 1);
        observed[size_t(i1 * n + i2)] += 1;
    }
    for (int i1 = 0; i1 < n; ++i1)
        for (int i2 = 0; i2 < n; ++i2) {
            const double full = 2.0 / (n * n) * N;  // barycentric density 2 on the half square
            expected[size_t(i1 * n + i2)] = i1 + i2 < n - 1 ? full : (i1 + i2 == n - 1 ? full / 2 : 0.0);
        }
    const auto r = chi2_from_counts(observed, expected);
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_EQ(observed.back(), 0.0);
}

// The solid-angle pdf of a triangle light as seen from several points: directions sampled by
// TriangleLight::sample against TriangleLight::pdfW of the point each direction hits. This
// checks the area-to-solid-angle conversion, not just the area sampling.
class TriangleLightDirections : public ::testing::TestWithParam<Vec3f> {};

TEST_P(TriangleLightDirections, MatchSolidAnglePdf) {
    const Vec3f a(-0.5f, -0.5f, 1.0f), b(0.7f, -0.4f, 1.2f), c(-0.2f, 0.8f, 0.9f);
    const TriangleLight tri(a, c, b, Rgb(1.0f));  // winding chosen so the normal faces down
    const Vec3f p = GetParam();
    const auto hit_point = [&](const Vec3f& w) -> std::optional<Vec3f> {
        // Moeller-Trumbore against the triangle.
        const Vec3f e1 = tri.e1, e2 = tri.e2, pv = cross(w, e2);
        const float det = dot(e1, pv);
        if (std::abs(det) < 1e-12f) return std::nullopt;
        const Vec3f tv = p - tri.p0;
        const float u = dot(tv, pv) / det;
        const Vec3f qv = cross(tv, e1);
        const float v = dot(w, qv) / det, t = dot(e2, qv) / det;
        if (u < 0 || v < 0 || u + v > 1 || t <= 0) return std::nullopt;
        return p + w * t;
    };
    const Vec3f centre = (a + b + c) / 3.0f;
    Chi2Options opt;
    opt.theta_power = 2;
    opt.integration_steps = 64;  // the silhouette cuts cells; resolve it finely
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = tri.sample_li(p, u);
            if (!s) return std::nullopt;
            return s->wi;
        },
        [&](const Vec3f& w) -> float {
            const auto q = hit_point(w);
            return q ? tri.pdf_li(p, *q) : 0.0f;
        },
        centre - p, opt);
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.describe();
}
INSTANTIATE_TEST_SUITE_P(ReferencePoints, TriangleLightDirections,
                         ::testing::Values(Vec3f(0.0f, 0.0f, 0.0f), Vec3f(1.5f, 0.3f, 0.6f), Vec3f(-0.3f, 0.1f, 0.5f)),
                         [](const auto& info) { return "point" + std::to_string(info.index); });

TEST(Sampling, EnvironmentLightIsUniformOverTheSphere) {
    const EnvironmentLight env{Rgb(1.0f)};
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> { return env.sample_li(Vec3f(0.0f), u)->wi; },
        [&](const Vec3f&) { return env.pdf_li(); }, {0.3f, 0.4f, 0.5f});
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
}

}  // namespace
}  // namespace pathlab::test
