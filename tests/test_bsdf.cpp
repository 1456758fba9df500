// The course's material (Lambert + normalised Phong): sampling against pdf (chi-square),
// sample/pdf/eval agreement, reciprocity, energy conservation.
#include <gtest/gtest.h>

#include "chi2.hpp"
#include "bsdfs/material.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();

struct Case {
    float rho_d, rho_s, exponent, theta_in;
};
std::string case_name(const ::testing::TestParamInfo<Case>& info) {
    const Case& c = info.param;
    std::string name = "d" + std::to_string(int(c.rho_d * 100)) + "_s" + std::to_string(int(c.rho_s * 100)) + "_n" +
                       std::to_string(int(c.exponent)) + "_theta" + std::to_string(int(c.theta_in * 10));
    return name;
}

class PhongSampling : public ::testing::TestWithParam<Case> {};

TEST_P(PhongSampling, MatchesItsPdfAndEval) {
    const Case c = GetParam();
    const Material m = make_phong(Rgb(c.rho_d), Rgb(c.rho_s), c.exponent);
    const Vec3f wi = incoming(c.theta_in);
    long pdf_mismatches = 0, eval_mismatches = 0;
    Chi2Options opt;
    opt.theta_power = c.exponent > 10 ? 2.0 : 1.0;  // resolve the lobe around the mirror direction
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = m.sample(wi, u);
            if (!s) return std::nullopt;
            const float p = m.pdf(wi, s->wo);
            if (std::abs(s->pdfW - p) > 1e-5f * p) ++pdf_mismatches;
            if (s->f != m.eval(wi, s->wo)) ++eval_mismatches;
            return s->wo;
        },
        [&](const Vec3f& wo) { return m.pdf(wi, wo); }, PhongMaterial::mirror(wi), opt);
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_EQ(pdf_mismatches, 0);
    EXPECT_EQ(eval_mismatches, 0);
    // The pdf integrates to 1 once the mass of rejected (below-surface) lobe samples is added.
    EXPECT_NEAR(r.pdf_integral + r.rejected_fraction, 1.0, 5e-3) << r.describe();
    EXPECT_LE(r.pdf_integral, 1.0 + 2e-3) << r.describe();
}

// The Phong lobe alone (rho_d = 0), and the diffuse + Phong mixture, for exponents 1, 90, 600
// and incoming directions from normal to grazing.
std::vector<Case> cases() {
    std::vector<Case> out;
    for (float n : {1.0f, 90.0f, 600.0f})
        for (float theta : {0.0f, 45.0f, 80.0f, 89.5f}) {
            out.push_back({0.0f, 0.7f, n, theta});
            out.push_back({0.4f, 0.5f, n, theta});
        }
    return out;
}
INSTANTIATE_TEST_SUITE_P(Lobes, PhongSampling, ::testing::ValuesIn(cases()), case_name);

TEST(PhongSampling, PureDiffuseIsCosineSampling) {
    const Material m = make_phong(Rgb(0.5f));
    const Vec3f wi = incoming(30);
    const auto r = chi2_directions([&](Vec2f u) -> std::optional<Vec3f> { return m.sample(wi, u)->wo; },
                                   [](const Vec3f& wo) { return cosine_hemisphere_pdf(wo); }, {0, 0, 1});
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
}

// Test of the test: returning the chosen lobe's pdf instead of the mixture's is a classic bug;
// the chi-square test must reject it.
TEST(PhongSampling, ChosenLobePdfInsteadOfTheMixtureIsRejected) {
    const PhongMaterial m{Rgb(0.4f), Rgb(0.5f), 20.0f};
    const Vec3f wi = incoming(45);
    // Which lobe generated a direction is unknown to pdf(), so emulate the bug consistently:
    // claim the density of the diffuse lobe alone, the one chosen most often.
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = m.sample(wi, u);
            return s ? std::optional<Vec3f>(s->wo) : std::nullopt;
        },
        [&](const Vec3f& wo) { return cosine_hemisphere_pdf(wo); }, PhongMaterial::mirror(wi));
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
}

TEST(Phong, IsReciprocal) {
    Sampler rng(3, 0, 0);
    for (float n : {1.0f, 90.0f, 600.0f}) {
        const Material m = make_phong(Rgb(0.3f, 0.4f, 0.5f), Rgb(0.5f), n);
        for (int i = 0; i < 10000; ++i) {
            const Vec3f a = square_to_uniform_hemisphere(rng.next2d()), b = square_to_uniform_hemisphere(rng.next2d());
            ASSERT_EQ(m.eval(a, b), m.eval(b, a));
        }
    }
}

TEST(Phong, IsZeroBelowTheSurfaceAndBehindTheLobe) {
    const Material m = make_phong(Rgb(0.5f), Rgb(0.5f), 90);
    EXPECT_EQ(m.eval({0, 0, 1}, normalize(Vec3f(1, 0, -0.1f))), Rgb(0.0f));
    EXPECT_EQ(m.eval(normalize(Vec3f(1, 0, -0.1f)), {0, 0, 1}), Rgb(0.0f));
    EXPECT_EQ(m.pdf({0, 0, 1}, normalize(Vec3f(1, 0, -0.1f))), 0.0f);
    // cos(alpha) < 0: no retro-reflection lobe from pow of a negative base with even n.
    const Vec3f wi = normalize(Vec3f(1, 0, 0.05f)), retro = wi;
    EXPECT_EQ(m.eval(wi, retro), Rgb(0.5f * kInvPi));
}

// Directional albedo a(wi) = integral of f cos over the hemisphere, by importance sampling.
std::pair<double, double> albedo(const Material& m, const Vec3f& wi, int n = 200'000) {
    Sampler rng(17, 0, 0);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const auto s = m.sample(wi, rng.next2d());
        const double v = s ? double(s->f.x) * s->wo.z / s->pdfW : 0.0;
        sum += v, sum2 += v * v;
    }
    const double mean = sum / n;
    return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n)};
}

TEST(Phong, ConservesEnergyAtEveryAngle) {
    for (float n : {1.0f, 90.0f, 600.0f})
        for (float theta : {0.0f, 30.0f, 60.0f, 80.0f, 89.0f}) {
            // The course's glossy walls: rho_d + rho_s = 0.902.
            const Material m = make_phong(Rgb(0.401961f), Rgb(0.5f), n);
            const auto [a, se] = albedo(m, incoming(theta));
            EXPECT_LE(a, 1.0 + 4 * se) << "n " << n << " theta " << theta;
            EXPECT_LE(a, 0.902 + 4 * se) << "n " << n << " theta " << theta;
        }
}

TEST(Phong, NormalIncidenceAlbedoIsRhoDPlusRhoS) {
    // At normal incidence the lobe is centred on the normal and (n+2)/(2pi) normalises
    // cos^n cos exactly: the albedo is rho_d + rho_s. Checks the normalisation constant.
    for (float n : {1.0f, 90.0f, 600.0f}) {
        const auto [a, se] = albedo(make_phong(Rgb(0.3f), Rgb(0.6f), n), {0, 0, 1});
        EXPECT_NEAR(a, 0.9, 4 * se + 1e-6) << "n " << n << ", albedo " << a << " +- " << se;
        EXPECT_LT(se, 2e-3);
    }
}

TEST(Phong, LambertAlbedoIsRhoAtEveryAngle) {
    for (float theta : {0.0f, 45.0f, 89.0f}) {
        const auto [a, se] = albedo(make_phong(Rgb(0.7f)), incoming(theta));
        EXPECT_NEAR(a, 0.7, 1e-5) << theta;  // f cos / pdf is constant for cosine sampling
    }
}

}  // namespace
}  // namespace pathlab::test
