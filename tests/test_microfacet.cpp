// Microfacet and Fresnel materials: the distributions (normalisation, Smith masking against
// an independent quadrature), Fresnel formulas, and per BSDF: sampling against pdf
// (chi-square over incoming angles and roughness), sample/pdf/eval agreement, reciprocity,
// and energy (white-furnace albedos against independent numerical integration of eval()).
#include <gtest/gtest.h>

#include <functional>

#include "chi2.hpp"
#include "scene/material.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();

Vec3f incoming(float theta_degrees) {
    const float t = theta_degrees * kPi / 180.0f;
    return normalize(Vec3f(std::sin(t) * 0.8f, std::sin(t) * 0.6f, std::cos(t)));
}

MicrofacetDistribution ggx(float au, float av = -1) { return {MicrofacetType::GGX, au, av < 0 ? au : av}; }
MicrofacetDistribution beckmann(float au, float av = -1) { return {MicrofacetType::Beckmann, au, av < 0 ? au : av}; }

// ---- numerical integration over microfacet normals ----------------------------------------
// Midpoint rule over the upper hemisphere of normals h, with theta_h = atan(a tan(pi t / 2)),
// t uniform: the nodes crowd where D has its mass (theta_h ~ a). f(h) is integrated against
// d omega_h. Independent of the samplers under test.
double integrate_normals(const std::function<double(const Vec3f&)>& f, double a, int nt = 600, int np = 600) {
    double sum = 0;
    for (int i = 0; i < nt; ++i) {
        const double t = (i + 0.5) / nt, x = std::tan(M_PI / 2 * t);
        const double theta = std::atan(a * x);
        const double dtheta_dt = a * (M_PI / 2) * (1 + x * x) / (1 + a * a * x * x);
        const double st = std::sin(theta), ct = std::cos(theta);
        for (int j = 0; j < np; ++j) {
            const double phi = 2 * M_PI * (j + 0.5) / np;
            const Vec3f h(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
            sum += f(h) * st * dtheta_dt;
        }
    }
    return sum * (2 * M_PI / np) / nt;
}

double mean_alpha(const MicrofacetDistribution& d) { return std::sqrt(double(d.alpha_u) * d.alpha_v); }

struct DistributionCase {
    MicrofacetDistribution d;
    std::string name;
};
std::vector<DistributionCase> distributions() {
    std::vector<DistributionCase> out;
    for (float a : {0.01f, 0.1f, 0.5f, 1.0f}) {
        out.push_back({ggx(a), "ggx_" + std::to_string(int(a * 100))});
        out.push_back({beckmann(a), "beckmann_" + std::to_string(int(a * 100))});
    }
    out.push_back({ggx(0.05f, 0.4f), "ggx_aniso_5_40"});
    out.push_back({beckmann(0.4f, 0.05f), "beckmann_aniso_40_5"});
    return out;
}

class Distribution : public ::testing::TestWithParam<DistributionCase> {};

// integral of D(h) cos(theta_h) = 1: the microfacets project onto the macro surface exactly.
TEST_P(Distribution, ProjectedAreaIsOne) {
    const MicrofacetDistribution& d = GetParam().d;
    const double I = integrate_normals([&](const Vec3f& h) { return double(d.D(h)) * h.z; }, mean_alpha(d));
    EXPECT_NEAR(I, 1.0, 1e-3);
}

// Smith's Lambda is defined by the projected area seen from w:
//   integral of max(0, w.h) D(h) = (1 + Lambda(w)) cos(theta_w),
// i.e. the visible-normal density G1(w) max(0, w.h) D(h) / cos(theta_w) integrates to 1.
// Checks each Lambda formula against its D, by quadrature.
TEST_P(Distribution, SmithLambdaMatchesTheProjectedArea) {
    const MicrofacetDistribution& d = GetParam().d;
    for (float theta : {0.0f, 30.0f, 60.0f, 80.0f, 89.0f}) {
        const Vec3f w = incoming(theta);
        const double I = integrate_normals([&](const Vec3f& h) { return double(d.D(h)) * std::max(0.0f, dot(w, h)); },
                                           mean_alpha(d), 800, 800);
        EXPECT_NEAR(I / (double(w.z) * (1 + d.lambda(w))), 1.0, 2e-3) << "theta " << theta;
    }
}
INSTANTIATE_TEST_SUITE_P(Microfacet, Distribution, ::testing::ValuesIn(distributions()),
                         [](const auto& info) { return info.param.name; });

// ---- Fresnel ----------------------------------------------------------------------------------

TEST(Fresnel, ConductorAgreesWithClosedFormsAndTheDielectricLimit) {
    // Normal incidence: ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2).
    for (auto [eta, k] : {std::pair{0.2f, 3.9f}, {1.66f, 9.22f}, {4.37f, 5.2f}}) {
        const float R0 = ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k);
        EXPECT_NEAR(fresnel_conductor(1.0f, eta, k), R0, 1e-5f);
        EXPECT_NEAR(fresnel_conductor(1e-4f, eta, k), 1.0f, 1e-3f);  // grazing: a mirror
    }
    // k = 0 is a dielectric of index eta, at every angle.
    for (float c = 0.05f; c <= 1; c += 0.05f)
        EXPECT_NEAR(fresnel_conductor(c, 1.5f, 0.0f), fresnel_dielectric(c, 1.5f), 1e-5f) << c;
    // eta = 0, k = 1 (material="none") reflects everything.
    for (float c = 0.01f; c <= 1; c += 0.01f) EXPECT_EQ(fresnel_conductor(c, 0.0f, 1.0f), 1.0f) << c;
    // Gold is yellow: red reflected more than blue.
    const Rgb au = fresnel_conductor(1.0f, named_conductor("Au")->eta, named_conductor("Au")->k);
    EXPECT_GT(au.x, 0.9f);
    EXPECT_LT(au.z, 0.6f);
}

TEST(Fresnel, DiffuseReflectanceAgreesWithEganHilgeman) {
    // Internal diffuse reflectance of a body of relative index eta (light inside, so
    // fresnel_diffuse_reflectance(1 / eta)) against the fit of Egan & Hilgeman (1973) used by
    // Jensen et al. 2001: -1.440/eta^2 + 0.710/eta + 0.668 + 0.0636 eta.
    for (float eta : {1.3f, 1.5f, 2.0f}) {
        const float fit = -1.440f / (eta * eta) + 0.710f / eta + 0.668f + 0.0636f * eta;
        EXPECT_NEAR(fresnel_diffuse_reflectance(1 / eta), fit, 5e-3f) << eta;
    }
    // Internal and external hemispherical reflectances: 1 - Fdr(1/eta) = (1 - Fdr(eta)) / eta^2.
    for (float eta : {1.3f, 1.5f, 2.0f})
        EXPECT_NEAR(1 - fresnel_diffuse_reflectance(1 / eta), (1 - fresnel_diffuse_reflectance(eta)) / (eta * eta), 1e-4f);
}

// ---- BSDFs: sampling ----------------------------------------------------------------------------

struct BsdfCase {
    std::string name;
    Material material;
    float theta_in;   // incoming angle, degrees
    float alpha;      // for the histogram's resolution and the name
    bool from_below = false;  // incoming from inside (dielectrics)
};

Vec3f case_wi(const BsdfCase& c) {
    Vec3f wi = incoming(c.theta_in);
    if (c.from_below) wi.z = -wi.z;
    return wi;
}

std::vector<BsdfCase> sampling_cases() {
    std::vector<BsdfCase> out;
    const auto tag = [](float a, float theta) {
        return "a" + std::to_string(int(std::round(a * 100))) + "_theta" + std::to_string(int(theta));
    };
    const ComplexIor gold = *named_conductor("Au");
    for (float a : {0.01f, 0.1f, 0.5f, 1.0f})
        for (float theta : {0.0f, 45.0f, 85.0f}) {
            out.push_back({"roughconductor_ggx_" + tag(a, theta), make_rough_conductor(ggx(a), gold), theta, a});
        }
    for (float theta : {0.0f, 60.0f})
        out.push_back({"roughconductor_ggx_aniso_" + tag(0.05f, theta), make_rough_conductor(ggx(0.05f, 0.4f)), theta, 0.05f});
    return out;
}

class BsdfSampling : public ::testing::TestWithParam<BsdfCase> {};

TEST_P(BsdfSampling, MatchesItsPdfAndEval) {
    const BsdfCase& c = GetParam();
    const Material& m = c.material;
    const Vec3f wi = case_wi(c);
    long pdf_mismatches = 0, eval_mismatches = 0, samples = 0;
    Chi2Options opt;
    opt.samples = 500'000;
    opt.theta_power = c.alpha < 0.05f ? 3.0 : (c.alpha < 0.3f ? 2.0 : 1.0);
    const Vec3f axis(-wi.x, -wi.y, wi.z);  // the mirror direction: centre of the reflection lobe
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = m.sample(wi, u);
            if (!s) return std::nullopt;
            ++samples;
            const float p = m.pdf(wi, s->wo);
            const Rgb f = m.eval(wi, s->wo);
            if (!(std::abs(s->pdfW - p) <= 1e-5f * p)) ++pdf_mismatches;
            if (!(max_component(abs(s->f - f)) <= 1e-5f * max_component(f))) ++eval_mismatches;
            return s->wo;
        },
        [&](const Vec3f& wo) { return m.pdf(wi, wo); }, axis, opt);
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_EQ(pdf_mismatches, 0) << "of " << samples;
    EXPECT_EQ(eval_mismatches, 0) << "of " << samples;
    // pdf() integrates to 1 once the mass of rejected samples (below the horizon) is added.
    EXPECT_NEAR(r.pdf_integral + r.rejected_fraction, 1.0, 5e-3) << r.describe();
}
INSTANTIATE_TEST_SUITE_P(Microfacet, BsdfSampling, ::testing::ValuesIn(sampling_cases()),
                         [](const auto& info) { return info.param.name; });

// For GGX the visible-normal sampler's weight f cos / pdf of a rough conductor is exactly
// F(wi.h) G2 / G1(wi): D and the 1 / (4 wi.h) Jacobian cancel (Heitz 2018).
TEST(RoughConductor, GgxSampleWeightIsFresnelTimesG2OverG1) {
    const ComplexIor cu = *named_conductor("Cu");
    Sampler rng(21, 0, 0);
    for (float a : {0.05f, 0.3f, 1.0f})
        for (float theta : {0.0f, 40.0f, 80.0f}) {
            const RoughConductorMaterial m{ggx(a, a * 0.6f), cu.eta, cu.k, Rgb(1.0f)};
            const Vec3f wi = incoming(theta);
            for (int i = 0; i < 2000; ++i) {
                const auto s = m.sample(wi, rng.next2d());
                if (!s) continue;
                const Vec3f h = normalize(wi + s->wo);
                const Rgb expected = fresnel_conductor(dot(wi, h), cu.eta, cu.k) *
                                     (m.distribution.G2(wi, s->wo) / m.distribution.G1(wi));
                const Rgb weight = s->f * (s->wo.z / s->pdfW);
                ASSERT_NEAR(weight.x, expected.x, 2e-4f * expected.x) << "alpha " << a << " theta " << theta;
                ASSERT_NEAR(weight.z, expected.z, 2e-4f * expected.z) << "alpha " << a << " theta " << theta;
            }
        }
}

// ---- BSDFs: energy ------------------------------------------------------------------------------

struct Estimate {
    double mean, se;
};

// Directional albedo (first channel) by the material's own importance sampling.
Estimate sampled_albedo(const Material& m, const Vec3f& wi, int n = 200'000, const std::function<double(const BsdfSample&)>& scale = nullptr) {
    Sampler rng(17, 0, 0);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const auto s = m.sample(wi, rng.next2d());
        double v = s ? double(s->f.x) * std::abs(s->wo.z) / s->pdfW : 0.0;
        if (s && scale) v *= scale(*s);
        sum += v, sum2 += v * v;
    }
    const double mean = sum / n;
    return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n)};
}

// Directional albedo of the reflection of a microfacet BRDF by quadrature over microfacet
// normals: wo = reflect(wi, h), d omega_o = 4 |wo.h| d omega_h. Uses only eval().
double reflection_albedo_by_quadrature(const Material& m, const Vec3f& wi, double a) {
    return integrate_normals(
        [&](const Vec3f& h) {
            const float c = dot(wi, h);
            if (c <= 0) return 0.0;
            const Vec3f wo = reflect(wi, h);
            if (wo.z <= 0) return 0.0;
            return double(m.eval(wi, wo).x) * wo.z * 4 * c;
        },
        a, 700, 700);
}

// White furnace for a rough conductor with F = 1 (material="none"): all energy lost is the
// single-scattering loss of shadowing-masking. The sampled albedo must equal the quadrature
// of eval() (an independent integration of the BRDF), stay below 1, approach 1 as the
// surface gets smooth, and fall with roughness at grazing angles.
TEST(RoughConductor, WhiteFurnaceAlbedoIsTheSingleScatteringEnergy) {
    for (bool use_ggx : {true, false}) {
        for (float theta : {0.0f, 45.0f, 80.0f}) {
            double previous = 2.0;
            for (float a : {0.01f, 0.1f, 0.5f, 1.0f}) {
                const Material m = make_rough_conductor(use_ggx ? ggx(a) : beckmann(a));
                const Vec3f wi = incoming(theta);
                const Estimate e = sampled_albedo(m, wi);
                const double q = reflection_albedo_by_quadrature(m, wi, a);
                const std::string what = std::string(use_ggx ? "ggx" : "beckmann") + " alpha " + std::to_string(a) +
                                         " theta " + std::to_string(theta) + ": sampled " + std::to_string(e.mean) +
                                         " +- " + std::to_string(e.se) + ", quadrature " + std::to_string(q);
                ::testing::Test::RecordProperty(what, "");
                EXPECT_NEAR(e.mean, q, 4 * e.se + 1e-3) << what;
                EXPECT_LE(e.mean, 1.0 + 4 * e.se + 1e-6) << what;  // 1e-6: float rounding of the weights
                if (a == 0.01f) { EXPECT_GT(q, 0.995) << what; }  // nearly smooth: nearly no loss
                if (theta == 80.0f) { EXPECT_LT(q, previous) << what; }
                previous = q;
            }
        }
    }
}

TEST(RoughConductor, IsReciprocal) {
    Sampler rng(3, 0, 0);
    for (const auto& d : {ggx(0.2f), ggx(0.05f, 0.5f), beckmann(0.3f)}) {
        const Material m = make_rough_conductor(d, *named_conductor("Au"));
        for (int i = 0; i < 10000; ++i) {
            const Vec3f a = square_to_uniform_hemisphere(rng.next2d()), b = square_to_uniform_hemisphere(rng.next2d());
            const Rgb fab = m.eval(a, b), fba = m.eval(b, a);
            ASSERT_LE(max_component(abs(fab - fba)), 1e-5f * max_component(fab) + 1e-30f);
        }
    }
}

TEST(RoughConductor, IsBlackFromBehindAndBelow) {
    const Material m = make_rough_conductor(ggx(0.3f));
    const Vec3f up = incoming(30), down(-0.2f, 0.1f, -0.97f);
    EXPECT_EQ(m.eval(up, normalize(down)), Rgb(0.0f));
    EXPECT_EQ(m.eval(normalize(down), up), Rgb(0.0f));
    EXPECT_FALSE(m.sample(normalize(down), {0.3f, 0.6f}));
    EXPECT_FALSE(m.is_delta());
}

// Test of the test: a GGX visible-normal pdf without its G1(wi) factor must be rejected by
// the chi-square test (at grazing incidence, where G1 differs most from 1).
TEST(RoughConductor, ChiSquareRejectsAVisibleNormalPdfWithoutG1) {
    const RoughConductorMaterial m{ggx(0.5f), Rgb(0.0f), Rgb(1.0f), Rgb(1.0f)};
    const Vec3f wi = incoming(80);
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = m.sample(wi, u);
            return s ? std::optional<Vec3f>(s->wo) : std::nullopt;
        },
        [&](const Vec3f& wo) {
            const float p = m.pdf(wi, wo);
            return p / m.distribution.G1(wi);
        },
        Vec3f(-wi.x, -wi.y, wi.z), Chi2Options{.samples = 500'000});
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
}

}  // namespace
}  // namespace pathlab::test
