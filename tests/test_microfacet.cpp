// Microfacet and Fresnel materials: the distributions (normalisation, Smith masking against
// an independent quadrature), Fresnel formulas, and per BSDF: sampling against pdf
// (chi-square over incoming angles and roughness), sample/pdf/eval agreement, reciprocity,
// and energy (white-furnace albedos against independent numerical integration of eval()).
#include <gtest/gtest.h>

#include <functional>

#include <fmt/format.h>

#include "chi2.hpp"
#include "bsdfs/material.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();

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

void PrintTo(const DistributionCase& c, std::ostream* os) { *os << c.name; }

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
    // Built when the test runs (not when tests are listed: rough plastic tabulates its
    // coating at construction, and every test process lists all cases).
    std::function<Material()> material;
    float theta_in;   // incoming angle, degrees
    float alpha;      // for the histogram's resolution and the name
    bool from_below = false;  // incoming from inside (dielectrics)
    // Dielectrics are tested one lobe at a time, each histogram centred on its lobe (the
    // other lobe's samples count as rejected): +1 reflection, -1 transmission, 0 both.
    int side = 0;
};

void PrintTo(const BsdfCase& c, std::ostream* os) { *os << c.name; }

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
            out.push_back({"roughconductor_ggx_" + tag(a, theta), [=] { return make_rough_conductor(ggx(a), gold); }, theta, a});
        }
    for (float theta : {0.0f, 60.0f}) {
        out.push_back({"roughconductor_ggx_aniso_" + tag(0.05f, theta), [=] { return make_rough_conductor(ggx(0.05f, 0.4f)); }, theta, 0.05f});
        for (float a : {0.1f, 0.5f})
            out.push_back({"roughconductor_beckmann_" + tag(a, theta), [=] { return make_rough_conductor(beckmann(a), gold); }, theta, a});
    }
    for (float a : {0.01f, 1.0f})
        out.push_back({"roughconductor_beckmann_" + tag(a, 85), [=] { return make_rough_conductor(beckmann(a), gold); }, 85, a});
    out.push_back({"roughconductor_beckmann_aniso_" + tag(0.4f, 60), [=] { return make_rough_conductor(beckmann(0.4f, 0.05f)); }, 60, 0.05f});
    // Rough glass from outside at every roughness, from inside below and beyond the critical
    // angle (41.6 degrees), anisotropic, and Beckmann.
    const auto both_lobes = [&](const std::string& name, const std::function<Material()>& m, float theta, float a,
                                bool below = false) {
        out.push_back({name + "_reflection", m, theta, a, below, +1});
        out.push_back({name + "_transmission", m, theta, a, below, -1});
    };
    for (float a : {0.01f, 0.1f, 0.5f, 1.0f})
        for (float theta : {0.0f, 45.0f, 85.0f})
            both_lobes("roughdielectric_ggx_" + tag(a, theta), [=] { return make_rough_dielectric(ggx(a), 1.5f, 1.0f); }, theta, a);
    for (float a : {0.1f, 0.5f})
        for (float theta : {30.0f, 60.0f})
            both_lobes("roughdielectric_ggx_inside_" + tag(a, theta), [=] { return make_rough_dielectric(ggx(a), 1.5f, 1.0f); }, theta, a, true);
    both_lobes("roughdielectric_ggx_aniso_" + tag(0.05f, 45), [=] { return make_rough_dielectric(ggx(0.05f, 0.3f), 1.5f, 1.0f); }, 45, 0.05f);
    for (float a : {0.1f, 0.5f}) {
        both_lobes("roughdielectric_beckmann_" + tag(a, 45), [=] { return make_rough_dielectric(beckmann(a), 1.5f, 1.0f); }, 45, a);
        both_lobes("roughdielectric_beckmann_inside_" + tag(a, 30), [=] { return make_rough_dielectric(beckmann(a), 1.5f, 1.0f); }, 30, a, true);
    }
    // Plastic: the diffuse part (its delta coating counts as rejected mass) and rough plastic.
    for (float theta : {0.0f, 45.0f, 85.0f}) {
        out.push_back({"plastic_" + tag(1, theta), [=] { return make_plastic(Rgb(0.5f, 0.3f, 0.2f)); }, theta, 1.0f});
        for (float a : {0.01f, 0.1f, 0.5f, 1.0f})
            out.push_back({"roughplastic_ggx_" + tag(a, theta), [=] { return make_rough_plastic(ggx(a), Rgb(0.5f, 0.3f, 0.2f)); }, theta, a});
    }
    out.push_back({"roughplastic_beckmann_" + tag(0.1f, 45), [=] { return make_rough_plastic(beckmann(0.1f), Rgb(0.5f)); }, 45, 0.1f});
    // principled: the default, every reflection lobe at once (anisotropic, metallic, clearcoat,
    // sheen), a nearly smooth one, and specular transmission from both sides, lobe by lobe.
    const auto principled = [](float roughness, float metallic, float spec_trans, float clearcoat, float anisotropic) {
        return [=] {
            PrincipledMaterial p;
            p.base_color = Rgb(0.6f, 0.4f, 0.3f);
            p.roughness = roughness, p.metallic = metallic, p.spec_trans = spec_trans, p.transmits = spec_trans > 0;
            p.clearcoat = clearcoat, p.clearcoat_gloss = 0.5f, p.anisotropic = anisotropic, p.sheen = 0.5f, p.spec_tint = 0.3f;
            return Material{p, false};
        };
    };
    for (float theta : {0.0f, 45.0f, 85.0f}) {
        out.push_back({"principled_default_" + tag(0.25f, theta), principled(0.5f, 0, 0, 0, 0), theta, 0.25f});
        out.push_back({"principled_all_lobes_" + tag(0.09f, theta), principled(0.3f, 0.4f, 0, 0.8f, 0.6f), theta, 0.05f});
    }
    out.push_back({"principled_smooth_" + tag(0.01f, 30), principled(0.1f, 0.5f, 0, 0, 0), 30, 0.01f});
    both_lobes("principled_glass_" + tag(0.16f, 45), principled(0.4f, 0.1f, 0.7f, 0.5f, 0), 45, 0.16f);
    both_lobes("principled_glass_inside_" + tag(0.16f, 30), principled(0.4f, 0.1f, 0.7f, 0, 0.5f), 30, 0.16f, true);
    both_lobes("principled_glass_inside_" + tag(0.16f, 60), principled(0.4f, 0.1f, 0.7f, 0, 0), 60, 0.16f, true);
    // principledthin: every lobe (specular and diffuse reflection and transmission, sheen, tint),
    // anisotropic, from behind, nearly smooth, and at an index whose transmission roughness
    // (0.65 eta - 0.35) r is below the reflection's.
    const auto thin = [](float roughness, float spec_trans, float diff_trans, float anisotropic, float eta) {
        return [=] {
            PrincipledThinMaterial p;
            p.base_color = Rgb(0.6f, 0.4f, 0.3f);
            p.roughness = roughness, p.spec_trans = spec_trans, p.diff_trans = diff_trans, p.anisotropic = anisotropic, p.eta = eta;
            p.sheen = 0.5f, p.spec_tint = 0.3f, p.flatness = 0.2f;
            return Material{p, true};
        };
    };
    both_lobes("principledthin_" + tag(0.16f, 45), thin(0.4f, 0.6f, 0.8f, 0, 1.5f), 45, 0.16f);
    both_lobes("principledthin_aniso_" + tag(0.09f, 30), thin(0.3f, 0.8f, 0.4f, 0.6f, 1.33f), 30, 0.05f);
    both_lobes("principledthin_behind_" + tag(0.16f, 60), thin(0.4f, 0.5f, 1.2f, 0, 1.5f), 60, 0.16f, true);
    both_lobes("principledthin_smooth_" + tag(0.01f, 20), thin(0.1f, 0.9f, 0.2f, 0, 1.2f), 20, 0.01f);
    return out;
}

class BsdfSampling : public ::testing::TestWithParam<BsdfCase> {};

TEST_P(BsdfSampling, MatchesItsPdfAndEval) {
    const BsdfCase& c = GetParam();
    const Material m = c.material();
    const Vec3f wi = case_wi(c);
    long pdf_mismatches = 0, eval_mismatches = 0, samples = 0, delta_samples = 0;
    Chi2Options opt;
    opt.samples = 500'000;
    opt.theta_power = c.alpha < 0.05f ? 3.0 : (c.alpha < 0.3f ? 2.0 : 1.0);
    // Centre of the lobe: the mirror direction, or the direction of smooth refraction (the
    // normal's other side beyond the critical angle).
    Vec3f axis(-wi.x, -wi.y, wi.z);
    const auto wrong_side = [&](const Vec3f& wo) { return c.side != 0 && (wo.z * wi.z > 0) != (c.side > 0); };
    if (c.side < 0 && std::holds_alternative<PrincipledThinMaterial>(m.model)) {
        axis = Vec3f(-wi.x, -wi.y, -wi.z);  // a thin sheet lets the mirrored direction through, unbent
    } else if (c.side < 0) {
        const auto* d = std::get_if<RoughDielectricMaterial>(&m.model);
        const auto* p = std::get_if<PrincipledMaterial>(&m.model);
        const float ext = d ? d->ext_ior : 1.0f, in = d ? d->int_ior : p->eta;
        const float eta_i = wi.z > 0 ? ext : in, eta_o = wi.z > 0 ? in : ext;
        const float r2 = (eta_i / eta_o) * (eta_i / eta_o) * (1 - wi.z * wi.z);
        axis = r2 < 1 ? normalize(Vec3f(-wi.x * eta_i / eta_o, -wi.y * eta_i / eta_o, std::copysign(std::sqrt(1 - r2), -wi.z)))
                      : Vec3f(0, 0, -std::copysign(1.0f, wi.z));
    }
    const auto r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = m.sample(wi, u);
            if (!s || wrong_side(s->wo)) return std::nullopt;
            if (s->delta) {  // plastic's coating: outside pdf()'s support, counted with the rejections
                ++delta_samples;
                return std::nullopt;
            }
            ++samples;
            const float p = m.pdf(wi, s->wo);
            const Rgb f = m.eval(wi, s->wo);
            if (!(std::abs(s->pdfW - p) <= 1e-5f * p)) ++pdf_mismatches;
            if (!(max_component(abs(s->f - f)) <= 1e-5f * max_component(f))) ++eval_mismatches;
            return s->wo;
        },
        [&](const Vec3f& wo) { return wrong_side(wo) ? 0.0f : m.pdf(wi, wo); }, axis, opt);
    ::testing::Test::RecordProperty("chi2", r.describe());
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_EQ(pdf_mismatches, 0) << "of " << samples;
    EXPECT_EQ(eval_mismatches, 0) << "of " << samples;
    // pdf() integrates to 1 once the mass of rejected samples (below the horizon) is added.
    EXPECT_NEAR(r.pdf_integral + r.rejected_fraction, 1.0, 5e-3) << r.describe();
    if (const auto* plastic = std::get_if<PlasticMaterial>(&m.model)) {
        // The coating's reflection is chosen with its probability P_s: a binomial count.
        const double ps = plastic->coat.specular_probability(plastic->coat.fresnel(wi.z)), n = opt.samples;
        EXPECT_NEAR(delta_samples, n * ps, 5 * std::sqrt(n * ps * (1 - ps)));
    } else {
        EXPECT_EQ(delta_samples, 0);
    }
}
INSTANTIATE_TEST_SUITE_P(Microfacet, BsdfSampling, ::testing::ValuesIn(sampling_cases()),
                         [](const auto& info) { return info.param.name; });

// With visible-normal sampling the weight f cos / pdf of a rough conductor is exactly
// F(wi.h) G2 / G1(wi): D and the 1 / (4 wi.h) Jacobian cancel (Heitz 2018).
TEST(RoughConductor, SampleWeightIsFresnelTimesG2OverG1) {
    const ComplexIor cu = *named_conductor("Cu");
    Sampler rng(21, 0, 0);
    for (bool use_ggx : {true, false})
    for (float a : {0.05f, 0.3f, 1.0f})
        for (float theta : {0.0f, 40.0f, 80.0f}) {
            const RoughConductorMaterial m{use_ggx ? ggx(a, a * 0.6f) : beckmann(a, a * 0.6f), cu.eta, cu.k, Rgb(1.0f)};
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

// ---- rough dielectric -----------------------------------------------------------------------------

// Reflectance R and transmittance T of a rough interface for light arriving along wi, by
// quadrature over microfacet normals (only eval() is used). T is the energy (radiance times
// eta^2) transmitted: the eval() of refraction carries the radiance factor (eta_i / eta_o)^2.
std::pair<double, double> interface_by_quadrature(const Material& m, Vec3f wi, float eta_i, float eta_o, double a) {
    const bool below = wi.z < 0;
    const auto flip = [&](Vec3f w) { return below ? Vec3f(w.x, w.y, -w.z) : w; };
    const Vec3f w = flip(wi);  // above the surface
    const double R = integrate_normals(
        [&](const Vec3f& h) {
            const float c = dot(w, h);
            const Vec3f wo = reflect(w, h);
            if (c <= 0 || wo.z <= 0) return 0.0;
            return double(m.eval(wi, flip(wo)).x) * wo.z * 4 * c;
        },
        a, 700, 700);
    const double T = integrate_normals(
        [&](const Vec3f& h) {
            const double c = dot(w, h), r = double(eta_i) / eta_o, k = 1 - r * r * (1 - c * c);
            if (c <= 0 || k < 0) return 0.0;
            const Vec3f wo = normalize(-w * float(r) + h * float(r * c - std::sqrt(k)));
            if (wo.z >= 0) return 0.0;
            const double co = dot(wo, h), den = eta_i * c + eta_o * co;
            const double jacobian = den * den / (double(eta_o) * eta_o * std::abs(co));  // d omega_o / d omega_h (Walter 2007, eq. 17)
            return double(m.eval(wi, flip(wo)).x) * std::abs(wo.z) * jacobian * (double(eta_o) * eta_o / (eta_i * eta_i));
        },
        a, 700, 700);
    return {R, T};
}

// Reflectance and transmittance (energy: refracted weights times (eta_o / eta_i)^2) of an
// interface by the material's own sampling, in one pass.
std::pair<Estimate, Estimate> sampled_interface(const Material& m, const Vec3f& wi, float eta_i, float eta_o, int n = 200'000) {
    Sampler rng(17, 0, 0);
    double sum[2] = {0, 0}, sum2[2] = {0, 0};
    for (int i = 0; i < n; ++i) {
        const auto s = m.sample(wi, rng.next2d());
        if (!s) continue;
        const bool t = (s->wo.z > 0) != (wi.z > 0);
        const double v = double(s->f.x) * std::abs(s->wo.z) / s->pdfW * (t ? double(eta_o) * eta_o / (eta_i * eta_i) : 1.0);
        sum[t] += v, sum2[t] += v * v;
    }
    const auto estimate = [&](int k) {
        const double mean = sum[k] / n;
        return Estimate{mean, std::sqrt(std::max(0.0, sum2[k] / n - mean * mean) / n)};
    };
    return {estimate(0), estimate(1)};
}

// Energy balance of rough glass: sampled reflectance and transmittance (energy) against the
// quadrature of eval(); R + T <= 1 (single scattering loses what shadowing-masking removes);
// nearly smooth glass splits like the smooth Fresnel equations, total internal reflection
// included.
TEST(RoughDielectric, ReflectionAndTransmissionConserveEnergy) {
    const float n = 1.5f;
    struct Incidence {
        float theta;
        bool inside;
    };
    for (bool use_ggx : {true, false})
        for (Incidence in : {Incidence{0, false}, {45, false}, {80, false}, {20, true}, {60, true}})
            for (float a : {0.01f, 0.1f, 0.5f, 1.0f}) {
                const Material m = make_rough_dielectric(use_ggx ? ggx(a) : beckmann(a), n, 1.0f);
                Vec3f wi = incoming(in.theta);
                if (in.inside) wi.z = -wi.z;
                const float eta_i = in.inside ? n : 1.0f, eta_o = in.inside ? 1.0f : n;
                const auto [R, T] = interface_by_quadrature(m, wi, eta_i, eta_o, a);
                const auto [r, t] = sampled_interface(m, wi, eta_i, eta_o);
                const std::string what = fmt::format("{} alpha {} theta {}{}: R {:.5f} +- {:.5f} (quadrature {:.5f}), "
                                                     "T {:.5f} +- {:.5f} (quadrature {:.5f})",
                                                     use_ggx ? "ggx" : "beckmann", a, in.theta, in.inside ? " inside" : "",
                                                     r.mean, r.se, R, t.mean, t.se, T);
                EXPECT_NEAR(r.mean, R, 4 * r.se + 1e-3) << what;
                EXPECT_NEAR(t.mean, T, 4 * t.se + 1e-3) << what;
                EXPECT_LE(R + T, 1.0 + 1e-3) << what;
                // Nearly smooth glass splits like smooth glass (away from grazing angles,
                // where even 0.01 rad of facet tilt moves the steep Fresnel term).
                if (a == 0.01f && in.theta <= 60) {
                    const float F = fresnel_dielectric(std::abs(wi.z), eta_o / eta_i);
                    EXPECT_NEAR(R, F, 1e-3) << what;
                    EXPECT_NEAR(T, 1 - F, 1e-3) << what;
                }
            }
}

// Radiance across an interface: f(wi, wo) / eta_i^2 = f(wo, wi) / eta_o^2 (Veach 1997, 5.2),
// which reduces to plain reciprocity for reflection.
TEST(RoughDielectric, ObeysTheGeneralisedReciprocity) {
    Sampler rng(4, 0, 0);
    const float n = 1.5f;
    for (const auto& d : {ggx(0.2f), ggx(0.05f, 0.5f), beckmann(0.3f)}) {
        const Material m = make_rough_dielectric(d, n, 1.0f);
        long nonzero = 0;
        for (int i = 0; i < 20000; ++i) {
            const Vec3f a = square_to_uniform_sphere(rng.next2d()), b = square_to_uniform_sphere(rng.next2d());
            const float ea = a.z > 0 ? 1.0f : n, eb = b.z > 0 ? 1.0f : n;
            const float fab = m.eval(a, b).x / (ea * ea), fba = m.eval(b, a).x / (eb * eb);
            ASSERT_NEAR(fab, fba, 1e-4f * std::max(fab, fba) + 1e-30f) << a.z << " " << b.z;
            nonzero += fab > 0;
        }
        EXPECT_GT(nonzero, 1000);
    }
}

// ---- plastic ----------------------------------------------------------------------------------------

// Diffuse albedo of the coated base (plastic.hpp), in closed form from Fdr:
// rho' (1 - F(cos_i)) (1 - Fdr_ext) / eta^2 = rho' (1 - F(cos_i)) (1 - Fdr_int).
double coated_diffuse_albedo(float rho, float cos_i, float eta, bool nonlinear) {
    const double fdr_int = fresnel_diffuse_reflectance(1 / eta);
    const double rho_eff = nonlinear ? rho / (1 - rho * fdr_int) : rho / (1 - fdr_int);
    return rho_eff * (1 - fresnel_dielectric(cos_i, eta)) * (1 - fdr_int);
}

TEST(Plastic, AlbedoIsTheCoatingsReflectionPlusTheTransmittedDiffuse) {
    for (bool nonlinear : {false, true})
        for (float rho : {1.0f, 0.5f})
            for (float theta : {0.0f, 45.0f, 80.0f, 89.0f}) {
                const float eta = 1.49f / 1.000277f;
                const Material m = make_plastic(Rgb(rho), Rgb(1.0f), 1.49f, 1.000277f, nonlinear);
                const Vec3f wi = incoming(theta);
                const Estimate e = sampled_albedo(m, wi);
                const double expected = fresnel_dielectric(wi.z, eta) + coated_diffuse_albedo(rho, wi.z, eta, nonlinear);
                EXPECT_NEAR(e.mean, expected, 4 * e.se + 1e-6) << "rho " << rho << " theta " << theta << " nonlinear " << nonlinear;
                // A white linear plastic is a white furnace: nothing is lost.
                if (rho == 1 && !nonlinear) { EXPECT_NEAR(expected, 1.0, 1e-4) << theta; }
            }
}

// Rough plastic, Mitsuba 3's model: its tables are the albedos of the rough dielectric interface
// that is its coating, measured here by that material's own sampling (an independent code path):
// T(mu) is the energy the interface transmits from outside (the radiance weight times eta^2,
// undoing the radiance convention), Fint the energy it reflects back of diffuse light from inside
// (cosine-weighted directions below the surface, reflections that stay below). A white linear base
// reflects at most what it receives (the facets' inter-reflections are lost, as in Mitsuba), and
// nearly all of it when the coating is nearly smooth.
TEST(RoughPlastic, CoatingTablesAreTheRoughDielectricsAlbedos) {
    const float int_ior = 1.49f, ext_ior = 1.000277f, eta = int_ior / ext_ior;
    for (bool use_ggx : {true, false})
        for (float a : {0.01f, 0.1f, 0.5f, 1.0f}) {
            const auto d = use_ggx ? ggx(a) : beckmann(a);
            const Material plastic = make_rough_plastic(d, Rgb(1.0f), Rgb(1.0f), int_ior, ext_ior);
            const auto& rp = std::get<RoughPlasticMaterial>(plastic.model);
            const Material interface = make_rough_dielectric(d, int_ior, ext_ior);
            const std::string name = fmt::format("{} alpha {}", use_ggx ? "ggx" : "beckmann", a);
            // Fint: wi cosine-distributed below the surface.
            Sampler rng(23, 0, 0);
            const int n = 200'000;
            double sum = 0, sum2 = 0;
            for (int i = 0; i < n; ++i) {
                Vec3f wi = square_to_cosine_hemisphere(rng.next2d());
                wi.z = -wi.z;
                const auto s = interface.sample(wi, rng.next2d());
                const double v = s && s->wo.z < 0 ? double(s->f.x) * std::abs(s->wo.z) / s->pdfW : 0.0;
                sum += v, sum2 += v * v;
            }
            const double fint = sum / n, fint_se = std::sqrt(std::max(0.0, sum2 / n - fint * fint) / n);
            EXPECT_NEAR(rp.coat.fdr, fint, 4 * fint_se + 2e-3) << name << ": Fint " << rp.coat.fdr << ", sampled " << fint << " +- " << fint_se;
            for (float theta : {0.0f, 60.0f, 85.0f}) {
                const Vec3f wi = incoming(theta);
                const Estimate t = sampled_albedo(interface, wi, 100'000,
                                                  [&](const BsdfSample& s) { return s.wo.z < 0 ? double(eta) * eta : 0.0; });
                const Estimate white = sampled_albedo(plastic, wi, 100'000);
                const std::string what = fmt::format("{} theta {}: T {:.5f}, sampled {:.5f} +- {:.5f}; white base {:.5f} +- {:.5f}",
                                                     name, theta, rp.T(wi.z), t.mean, t.se, white.mean, white.se);
                EXPECT_NEAR(rp.T(wi.z), t.mean, 4 * t.se + 3e-3) << what;  // 3e-3: T is interpolated between 64 nodes
                EXPECT_LE(white.mean, 1.0 + 4 * white.se) << what;
                if (a == 0.01f && theta < 80) { EXPECT_NEAR(white.mean, 1.0, 4 * white.se + 1e-2) << what; }
            }
        }
}

TEST(Plastic, SmoothAndRoughAreReciprocal) {
    Sampler rng(5, 0, 0);
    for (const Material& m : {make_plastic(Rgb(0.3f, 0.5f, 0.7f)), make_plastic(Rgb(0.8f), Rgb(0.5f), 1.6f, 1.0f, true),
                              make_rough_plastic(ggx(0.2f), Rgb(0.3f, 0.5f, 0.7f)), make_rough_plastic(beckmann(0.4f), Rgb(0.6f))}) {
        for (int i = 0; i < 10000; ++i) {
            const Vec3f a = square_to_uniform_hemisphere(rng.next2d()), b = square_to_uniform_hemisphere(rng.next2d());
            const Rgb fab = m.eval(a, b), fba = m.eval(b, a);
            ASSERT_LE(max_component(abs(fab - fba)), 1e-5f * max_component(fab));
        }
    }
}

TEST(Materials, DeltaClassification) {
    EXPECT_TRUE(make_mirror().is_delta());
    EXPECT_TRUE(make_conductor(*named_conductor("Au")).is_delta());
    EXPECT_TRUE(make_dielectric(1.5f).is_delta());
    EXPECT_FALSE(make_plastic(Rgb(0.5f)).is_delta());  // a delta coating over a diffuse base
    EXPECT_FALSE(make_rough_plastic(ggx(0.1f), Rgb(0.5f)).is_delta());
    EXPECT_FALSE(make_rough_dielectric(ggx(0.1f), 1.5f).is_delta());
    EXPECT_TRUE(make_rough_dielectric(ggx(0.1f), 1.5f).is_dielectric());
    EXPECT_FALSE(make_rough_dielectric(ggx(0.1f), 1.5f).two_sided);
}

// Every material at extreme roughness (the clamp 1e-4, and 10), anisotropy, and directions
// up to exactly grazing: values, pdfs and weights are finite and non-negative, samples unit.
TEST(Materials, StayFiniteAtExtremes) {
    std::vector<Material> materials;
    for (float a : {0.0f, 1e-4f, 0.01f, 1.0f, 10.0f})
        for (const auto& d : {ggx(a), beckmann(a), ggx(a, 0.5f), beckmann(0.5f, a)}) {
            materials.push_back(make_rough_conductor(d, *named_conductor("Cr")));
            materials.push_back(make_rough_dielectric(d, 1.5f, 1.0f));
            materials.push_back(make_rough_dielectric(d, 1.0f, 1.33f));
            materials.push_back(make_rough_plastic(d, Rgb(0.5f), Rgb(1.0f), 1.5f, 1.0f, true));
        }
    materials.push_back(make_plastic(Rgb(0.5f)));
    materials.push_back(make_conductor(*named_conductor("Al")));
    Sampler rng(8, 0, 0);
    const auto direction = [&]() {
        Vec3f w = square_to_uniform_sphere(rng.next2d());
        const float r = rng.next1d();
        if (r < 0.1f) w.z = 0;                  // exactly grazing
        else if (r < 0.2f) w.z *= 1e-6f;        // nearly grazing
        else if (r < 0.25f) w = Vec3f(0, 0, w.z > 0 ? 1.0f : -1.0f);  // exactly normal
        return normalize(w);
    };
    long samples = 0;
    for (const Material& m : materials)
        for (int i = 0; i < 3000; ++i) {
            const Vec3f wi = direction(), wo = direction();
            float p = 0;
            const Rgb f = m.eval_and_pdf(wi, wo, p);
            ASSERT_TRUE(is_finite(f) && min_component(f) >= 0) << f.x << " " << f.y << " " << f.z;
            ASSERT_TRUE(std::isfinite(p) && p >= 0) << p;
            if (const auto s = m.sample(wi, rng.next2d())) {
                ++samples;
                ASSERT_NEAR(length(s->wo), 1.0f, 1e-4f);
                ASSERT_TRUE(is_finite(s->f) && min_component(s->f) >= 0);
                ASSERT_TRUE(std::isfinite(s->pdfW) && s->pdfW > 0) << s->pdfW;
                ASSERT_TRUE(is_finite(s->f * (std::abs(s->wo.z) / s->pdfW)));
            }
        }
    EXPECT_GT(samples, 100000);
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
    ::testing::Test::RecordProperty("chi2", r.describe());
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
}

}  // namespace
}  // namespace pathlab::test
