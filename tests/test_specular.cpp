// Delta BSDFs (mirror, glass) and spherical emitters.
#include <gtest/gtest.h>

#include "chi2.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

TEST(Dielectric, FresnelAtNormalIncidenceAndTotalInternalReflection) {
    float cos_t = 0;
    const float n = 1.5f;
    EXPECT_NEAR(fresnel_dielectric(1.0f, n, &cos_t), ((n - 1) / (n + 1)) * ((n - 1) / (n + 1)), 1e-6f);
    EXPECT_NEAR(cos_t, 1.0f, 1e-6f);
    // From inside glass beyond the critical angle asin(1/1.5) = 41.8 degrees: everything reflects.
    EXPECT_EQ(fresnel_dielectric(std::cos(50.0f * kPi / 180), 1 / n, &cos_t), 1.0f);
    EXPECT_LT(fresnel_dielectric(std::cos(40.0f * kPi / 180), 1 / n, &cos_t), 1.0f);
}

TEST(Dielectric, SamplesObeySnellsLawAndSumToOne) {
    const DielectricMaterial glass{1.5f, 1.0f};
    Sampler rng(5, 0, 0);
    for (int i = 0; i < 1000; ++i) {
        Vec3f wi = square_to_uniform_sphere(rng.next2d());  // from outside (z > 0) and inside
        const auto s = glass.sample(wi, rng.next2d());
        ASSERT_TRUE(s);
        ASSERT_TRUE(s->delta);
        ASSERT_NEAR(length(s->wo), 1.0f, 1e-5f);
        const bool reflected = (s->wo.z > 0) == (wi.z > 0);
        const float eta_i = wi.z > 0 ? 1.0f : 1.5f, eta_o = s->wo.z > 0 ? 1.0f : 1.5f;
        const float sin_i = std::sqrt(std::max(0.0f, 1 - wi.z * wi.z)), sin_o = std::sqrt(std::max(0.0f, 1 - s->wo.z * s->wo.z));
        if (!reflected) {
            ASSERT_NEAR(eta_i * sin_i, eta_o * sin_o, 1e-4f);
            // The weight f cos / pdf is (eta_wi / eta_wo)^2.
            ASSERT_NEAR(s->f.x * std::abs(s->wo.z) / s->pdfW, (eta_i / eta_o) * (eta_i / eta_o), 1e-4f);
        } else {
            ASSERT_NEAR(s->f.x * std::abs(s->wo.z) / s->pdfW, 1.0f, 1e-5f);
        }
    }
}

// Snell's window: seen from inside water (n = 1.333), the whole sky above is squeezed into a
// cone of half-angle asin(1 / n) = 48.6 degrees around the normal; beyond it, light from
// inside is totally reflected.
TEST(Dielectric, SnellsWindowAndTotalInternalReflection) {
    const float n = 1.333f, critical = std::asin(1 / n);
    const DielectricMaterial water{n, 1.0f};
    Sampler rng(6, 0, 0);
    float widest = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f wi = square_to_uniform_hemisphere(rng.next2d());  // sky directions
        if (wi.z < 1e-3f) continue;                                   // F would round to 1
        const auto s = water.sample(wi, {0x1.fffffep-1f, 0.5f});      // u.x > F: refraction
        ASSERT_TRUE(s);
        ASSERT_LT(s->wo.z, 0);
        const float theta_t = std::acos(-s->wo.z);
        ASSERT_LE(theta_t, critical + 1e-4f);
        widest = std::max(widest, theta_t);
    }
    EXPECT_GT(widest, critical - 0.02f);  // the window is filled to its rim
    // From inside, outside the window: every sample reflects, whatever u.
    for (float theta : {49.0f, 60.0f, 89.0f}) {
        const float t = theta * kPi / 180;
        const Vec3f wi(std::sin(t), 0, -std::cos(t));
        for (float u : {0.0f, 0.5f, 0.999f}) {
            const auto s = water.sample(wi, {u, 0.5f});
            ASSERT_TRUE(s);
            EXPECT_LT(s->wo.z, 0) << theta;  // stays inside
            EXPECT_NEAR(s->f.x * std::abs(s->wo.z) / s->pdfW, 1.0f, 1e-6f) << theta;
        }
    }
    // Just inside the window, some light leaves.
    const float t = 48.0f * kPi / 180;
    const auto s = water.sample(Vec3f(std::sin(t), 0, -std::cos(t)), {0.999f, 0.5f});
    ASSERT_TRUE(s);
    EXPECT_GT(s->wo.z, 0);
}

TEST(Mirror, ReflectsAboutTheNormal) {
    const ConductorMaterial m{Rgb(0.0f), Rgb(1.0f), Rgb(0.9f)};  // material="none" scaled by 0.9
    const Vec3f wi = normalize(Vec3f(0.3f, -0.4f, 0.8f));
    const auto s = m.sample(wi, {0.5f, 0.5f});
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->wo.x, -wi.x, 1e-7f);
    EXPECT_NEAR(s->wo.z, wi.z, 1e-7f);
    EXPECT_NEAR(s->f.x * s->wo.z / s->pdfW, 0.9f, 1e-6f);
    EXPECT_EQ(m.eval(wi, s->wo), Rgb(0.0f));
    EXPECT_EQ(m.pdf(wi, s->wo), 0.0f);
}

// A constant environment around objects that neither absorb nor emit: every pixel sees Le.
// Glass and mirror spheres on a white diffuse floor; all path tracers.
SceneDescription specular_furnace(const Rgb& Le) {
    SceneDescription d;
    d.name = "specular furnace";
    d.camera = Camera::look_along({0, -4, 1}, {0, 1, -0.25f}, {0, 0, 1}, 40.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(1.0f)), make_dielectric(1.5f, 1.0f), make_mirror(Rgb(1.0f))};
    MeshDesc floor;
    floor.positions = {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}};
    floor.triangles = {{0, 1, 2}, {2, 3, 0}};
    d.meshes.push_back(floor);
    d.spheres.push_back(SphereDesc{{-0.6f, 0, 0.5f}, 0.5f, 1});
    d.spheres.push_back(SphereDesc{{0.6f, 0.3f, 0.5f}, 0.5f, 2});
    d.lights = {EnvironmentLight{Le}};
    return d;
}

class SpecularFurnace : public ::testing::TestWithParam<std::string> {};

TEST_P(SpecularFurnace, GlassAndMirrorStayUniform) {
    const Rgb Le(0.25f, 0.5f, 1.0f);
    const RenderResult r = render_scene(specular_furnace(Le), GetParam(), 12, 12, 2048, 8);
    const AgreementResult a = test_agreement(r.film.mean(), r.film.standard_error(), Image(12, 12, Le), Image());
    EXPECT_TRUE(a.agree) << a.describe();
    EXPECT_EQ(r.stats.invalid_samples, 0u);
}
INSTANTIATE_TEST_SUITE_P(PathTracers, SpecularFurnace, ::testing::Values("pt-naive", "pt-mis3", "pt-mis", "bdpt"),
                         [](const auto& info) {
                             std::string n = info.param;
                             std::replace(n.begin(), n.end(), '-', '_');
                             return n;
                         });

TEST(SpecularFurnace, AMirrorThatAbsorbsIsDetected) {
    // Test of the test: a mirror of reflectance 0.9 loses energy, which the furnace must see.
    SceneDescription d = specular_furnace(Rgb(0.5f));
    d.materials[2] = make_mirror(Rgb(0.9f));
    const RenderResult r = render_scene(d, "pt-mis", 12, 12, 2048, 8);
    EXPECT_FALSE(test_agreement(r.film.mean(), r.film.standard_error(), Image(12, 12, Rgb(0.5f)), Image()).agree);
}

// Spherical emitters sample points uniformly by area and reject those facing away. Tested in
// the sphere's own area measure, where cell probabilities are exact: bands of equal height in
// z' (the axis towards the reference point) have equal area, and the visible cap is z' > r/d,
// which is placed on a band edge.
TEST(SphereLight, SamplesAreUniformOverTheVisibleCap) {
    const SphereLight light{{0.3f, -0.2f, 2.0f}, 0.7f, false, Rgb(1.0f)};
    const Vec3f p(0, 0, 0);
    const float d = length(light.center - p), z0 = light.radius / d;
    const Frame frame(normalize(p - light.center));
    const int bands_above = 20, bands_below = 20, sectors = 24, N = 1'000'000;
    std::vector<double> observed(size_t((bands_above + bands_below) * sectors) + 1, 0.0), expected(observed.size(), 0.0);
    const auto band_of = [&](float z) {
        if (z >= z0) return bands_below + std::min(bands_above - 1, int((z - z0) / (1 - z0) * bands_above));
        return std::min(bands_below - 1, int((z + 1) / (z0 + 1) * bands_below));
    };
    Sampler rng(13, 0, 0);
    long pdf_mismatches = 0;
    for (int i = 0; i < N; ++i) {
        const auto s = light.sample_li(p, rng.next2d());
        if (!s) {
            observed.back() += 1;
            continue;
        }
        const float expected_pdf = light.pdf_li(p, s->point, s->normal);
        if (std::abs(s->pdfW - expected_pdf) > 1e-4f * expected_pdf) ++pdf_mismatches;
        const Vec3f l = frame.to_local((s->point - light.center) / light.radius);
        double phi = std::atan2(l.y, l.x);
        if (phi < 0) phi += 2 * M_PI;
        const int sector = std::min(sectors - 1, int(phi / (2 * M_PI) * sectors));
        observed[size_t(band_of(l.z) * sectors + sector)] += 1;
    }
    // Area fraction of a band [z_a, z_b] is (z_b - z_a) / 2; only bands above z0 are sampled.
    for (int b = 0; b < bands_above; ++b)
        for (int k = 0; k < sectors; ++k)
            expected[size_t((bands_below + b) * sectors + k)] = N * ((1 - z0) / bands_above) / 2 / sectors;
    expected.back() = N * (1 + z0) / 2;
    const auto r = chi2_from_counts(observed, expected);
    EXPECT_GT(r.p_value, suite_chi2_alpha()) << r.describe();
    EXPECT_EQ(r.zero_pdf_samples, 0) << "samples on the side facing away";
    EXPECT_EQ(pdf_mismatches, 0);
}

// The solid-angle pdf integrates to the visible fraction (1 - r/d) / 2: estimated without
// bias by sampling the cone the sphere subtends uniformly.
TEST(SphereLight, SolidAnglePdfIntegratesToTheVisibleFraction) {
    const SphereLight light{{0.3f, -0.2f, 2.0f}, 0.7f, false, Rgb(1.0f)};
    const Vec3f p(0, 0, 0);
    const Vec3f axis = normalize(light.center - p);
    const float d = length(light.center - p), cos_max = std::sqrt(1 - (light.radius / d) * (light.radius / d));
    const Frame frame(axis);
    Sampler rng(14, 0, 0);
    const int N = 400'000;
    double sum = 0, sum2 = 0;
    const double cone = 2 * M_PI * (1 - cos_max);
    for (int i = 0; i < N; ++i) {
        const Vec2f u = rng.next2d();
        const float z = 1 - u.x * (1 - cos_max), rxy = std::sqrt(std::max(0.0f, 1 - z * z));
        const Vec3f w = frame.to_world({rxy * std::cos(2 * kPi * u.y), rxy * std::sin(2 * kPi * u.y), z});
        const Vec3f f = p - light.center;
        const float b = dot(f, w), disc = b * b - (dot(f, f) - light.radius * light.radius);
        double v = 0;
        if (disc >= 0) {
            const Vec3f q = p + w * (-b - std::sqrt(disc));
            v = light.pdf_li(p, q, normalize(q - light.center)) * cone;
        }
        sum += v, sum2 += v * v;
    }
    const double mean = sum / N, se = std::sqrt((sum2 / N - mean * mean) / N);
    EXPECT_NEAR(mean, (1 - light.radius / d) / 2, 4 * se + 1e-4) << "se " << se;
}

// The camera inside an emitting sphere whose normals point inwards: L = Le / (1 - rho).
TEST(SphereLight, EmittingSphereEnclosureGivesLeOverOneMinusRho) {
    SceneDescription d;
    d.name = "sphere enclosure";
    d.camera = Camera::look_along({0.1f, 0, 0.2f}, {1, 0.2f, 0.1f}, {0, 0, 1}, 60.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(0.5f))};
    SphereDesc s{{0, 0, 0}, 2.0f, 0, true, Rgb(0.4f)};
    d.spheres.push_back(s);
    for (const char* a : {"pt-naive", "pt-mis3", "pt-mis"}) {
        const RenderResult r = render_scene(d, a, 8, 8, 2048, 9);
        const AgreementResult ag = test_agreement(r.film.mean(), r.film.standard_error(), Image(8, 8, Rgb(0.8f)), Image());
        EXPECT_TRUE(ag.agree) << a << ": " << ag.describe();
    }
}

}  // namespace
}  // namespace pathlab::test
