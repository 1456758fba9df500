// Emission sampling of every light type (the origins and directions light paths start from)
// against its own densities: chi-square of the directions against pdfW and of the origins
// against pdfA (mapped to directions, so the same harness judges them), the densities each
// sample reports equal pdf_emission(), and the densities integrate to 1.
#include <gtest/gtest.h>

#include "chi2.hpp"
#include "lights/light.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();
const SceneSphere kSphere{{0.5f, -0.25f, 1.0f}, 2.5f};

// Chi-square of the emitted directions of `light` for one fixed origin sample.
Chi2Result emitted_directions(const Light& light, Vec2f u_pos, const Vec3f& axis, float* mismatch = nullptr) {
    const auto first = sample_emission(light, u_pos, {0.5f, 0.5f}, kSphere);
    EXPECT_TRUE(first.has_value());
    float worst = 0;
    const Chi2Result r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = sample_emission(light, u_pos, u, kSphere);
            if (!s) return std::nullopt;
            const EmissionPdf p = pdf_emission(light, s->origin, s->normal, s->direction, kSphere);
            worst = std::max({worst, std::abs(p.pdfW - s->pdfW) / s->pdfW, std::abs(p.pdfA - s->pdfA) / s->pdfA});
            return s->direction;
        },
        [&](const Vec3f& w) { return pdf_emission(light, first->origin, first->normal, w, kSphere).pdfW; }, axis);
    if (mismatch) *mismatch = worst;
    return r;
}

TEST(LightEmission, PointLightEmitsUniformlyFromItsPosition) {
    const Light light = PointLight{{0.1f, 0.2f, 0.3f}, Rgb(2.0f)};
    float mismatch = 1;
    const Chi2Result r = emitted_directions(light, {0.3f, 0.7f}, {0.3f, 0.4f, 0.5f}, &mismatch);
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
    EXPECT_EQ(mismatch, 0.0f);
    const auto s = sample_emission(light, {0.9f, 0.1f}, {0.2f, 0.6f}, kSphere);
    EXPECT_EQ(s->origin, Vec3f(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(s->pdfA, 1.0f);  // a delta position
    EXPECT_EQ(s->Le, Rgb(2.0f));
}

TEST(LightEmission, TriangleEmitsCosineWeightedAroundItsNormal) {
    const TriangleLight tri({0.3f, -1.0f, 2.0f}, {2.5f, 0.5f, 1.0f}, {-0.7f, 1.5f, 0.2f}, Rgb(1.0f));
    float mismatch = 1;
    const Chi2Result r = emitted_directions(tri, {0.3f, 0.6f}, tri.normal, &mismatch);
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    EXPECT_EQ(mismatch, 0.0f);
    // Nothing leaves through the back.
    for (float u = 0.05f; u < 1; u += 0.1f) {
        const auto s = tri.sample_emission({u, 0.4f}, {0.7f, u}, kSphere);
        ASSERT_TRUE(s);
        EXPECT_GT(dot(s->direction, tri.normal), 0.0f);
        EXPECT_FLOAT_EQ(s->cos, dot(s->direction, tri.normal));
        EXPECT_FLOAT_EQ(s->pdfA * tri.area, 1.0f);
    }
}

TEST(LightEmission, SpherePointsAreUniformOverItsSurface) {
    for (const bool inward : {false, true}) {
        const SphereLight sphere{{0.3f, -0.2f, 2.0f}, 0.7f, inward, Rgb(1.0f)};
        // Origins, as directions from the centre: density pdfA r^2 per unit solid angle.
        const auto r = chi2_directions(
            [&](Vec2f u) -> std::optional<Vec3f> {
                const auto s = sphere.sample_emission(u, {0.5f, 0.5f}, kSphere);
                if (!s) return std::nullopt;
                return (s->origin - sphere.center) / sphere.radius;
            },
            [&](const Vec3f&) { return sphere.sample_emission({0.1f, 0.2f}, {0.5f, 0.5f}, kSphere)->pdfA * 0.49f; },
            {0.2f, 0.3f, 0.9f});
        EXPECT_GT(r.p_value, kAlpha) << r.describe();
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
        // Directions around the (inward or outward) normal of one origin.
        const auto s = sphere.sample_emission({0.3f, 0.8f}, {0.5f, 0.5f}, kSphere);
        EXPECT_NEAR(dot(s->normal, (s->origin - sphere.center) / sphere.radius), inward ? -1.0f : 1.0f, 1e-5);
        float mismatch = 1;
        const Chi2Result d = emitted_directions(sphere, {0.3f, 0.8f}, s->normal, &mismatch);
        EXPECT_GT(d.p_value, kAlpha) << d.describe();
        EXPECT_NEAR(d.pdf_integral, 1.0, 1e-3);
        EXPECT_EQ(mismatch, 0.0f);
    }
}

// The entry disk of lights at infinity, mapped to the hemisphere by Malley's projection
// (uniform on the unit disk becomes cos / pi): density pdfA R^2 cos.
Chi2Result entry_disk_points(const Light& light, Vec2f u_dir) {
    const auto first = sample_emission(light, {0.5f, 0.5f}, u_dir, kSphere);
    const Frame frame(first->direction);
    const Vec3f disk_centre = kSphere.center - first->direction * kSphere.radius;
    return chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = sample_emission(light, u, u_dir, kSphere);
            if (!s) return std::nullopt;
            const Vec3f q = frame.to_local((s->origin - disk_centre) / kSphere.radius);
            EXPECT_NEAR(q.z, 0.0f, 1e-5);  // on the disk, perpendicular to the direction
            return Vec3f(q.x, q.y, std::sqrt(std::max(0.0f, 1 - q.x * q.x - q.y * q.y)));
        },
        [&](const Vec3f& w) { return w.z > 0 ? first->pdfA * kSphere.radius * kSphere.radius * w.z : 0.0f; }, {0, 0, 1});
}

TEST(LightEmission, EnvironmentEmitsEveryDirectionFromTheEntryDisk) {
    const Light env = EnvironmentLight{Rgb(0.5f)};
    float mismatch = 1;
    const Chi2Result d = emitted_directions(env, {0.3f, 0.3f}, {0.1f, -0.5f, 0.7f}, &mismatch);
    EXPECT_GT(d.p_value, kAlpha) << d.describe();
    EXPECT_NEAR(d.pdf_integral, 1.0, 1e-4);
    EXPECT_EQ(mismatch, 0.0f);
    const Chi2Result p = entry_disk_points(env, {0.3f, 0.8f});
    EXPECT_GT(p.p_value, kAlpha) << p.describe();
    EXPECT_NEAR(p.pdf_integral, 1.0, 1e-4);
}

TEST(LightEmission, DirectionalLightEmitsItsDirectionFromTheEntryDisk) {
    const Vec3f dir = normalize(Vec3f(0.2f, -0.3f, -1.0f));
    const Light sun = DirectionalLight{dir, Rgb(3.0f)};
    const auto s = sample_emission(sun, {0.2f, 0.9f}, {0.4f, 0.1f}, kSphere);
    EXPECT_EQ(s->direction, dir);
    EXPECT_EQ(s->pdfW, 1.0f);  // a delta direction
    const Chi2Result p = entry_disk_points(sun, {0.0f, 0.0f});
    EXPECT_GT(p.p_value, kAlpha) << p.describe();
    EXPECT_NEAR(p.pdf_integral, 1.0, 1e-4);
}

// Every ray that meets the scene's bounding sphere leaves the entry disk of its direction:
// otherwise lights at infinity would miss part of the scene.
TEST(LightEmission, TheEntryDiskCoversTheBoundingSphere) {
    Sampler rng(3, 0, 0);
    for (int i = 0; i < 10000; ++i) {
        const Vec3f d = square_to_uniform_sphere(rng.next2d());
        const Vec3f x = kSphere.center + square_to_uniform_sphere(rng.next2d()) * (kSphere.radius * std::cbrt(rng.next1d()));
        const Frame f(d);
        const Vec3f rel = f.to_local(x - kSphere.center);
        EXPECT_LE(rel.x * rel.x + rel.y * rel.y, kSphere.radius * kSphere.radius * 1.0001f);
        EXPECT_GE(rel.z, -kSphere.radius * 1.0001f);  // the disk lies upstream of every point
    }
}

// Tests of the tests: a triangle claiming uniform hemisphere emission, and a sphere light
// whose origins are claimed with the density of a sphere of twice the area, must fail.
TEST(LightEmission, Chi2DetectsAWrongEmissionDensity) {
    const TriangleLight tri({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, Rgb(1.0f));
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> { return tri.sample_emission({0.3f, 0.3f}, u, kSphere)->direction; },
        [&](const Vec3f& w) { return uniform_hemisphere_pdf(w); }, tri.normal);
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
    const SphereLight sphere{{0, 0, 0}, 1.0f, false, Rgb(1.0f)};
    const auto a = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> { return sphere.sample_emission(u, {0.5f, 0.5f}, kSphere)->origin; },
        [&](const Vec3f&) { return 0.5f * sphere.sample_emission({0.1f, 0.2f}, {0.5f, 0.5f}, kSphere)->pdfA; }, {0, 0, 1});
    EXPECT_GT(std::abs(a.pdf_integral - 1.0), 0.1);
}

}  // namespace
}  // namespace pathlab::test
