// BSDFs with a shading context: in importance mode f(wi, wo) equals radiance mode's f(wo, wi)
// (the adjoint BSDF), including the eta^2 of refraction, and with a shading normal the
// adjoint carries Veach's correction; reverse pdfs are pdf() with the directions swapped;
// sampled lobes carry the right flags. Radiance mode is the plain model, bit for bit.
#include <gtest/gtest.h>

#include <functional>

#include "bsdfs/material.hpp"
#include "core/sampling.hpp"
#include "samplers/sampler.hpp"

namespace pathlab::test {
namespace {

struct Case {
    std::string name;
    Material material;
};

std::vector<Case> materials() {
    const MicrofacetDistribution ggx(MicrofacetType::GGX, 0.3f, 0.3f), aniso(MicrofacetType::Beckmann, 0.4f, 0.1f);
    return {{"phong", make_phong(Rgb(0.4f, 0.3f, 0.2f), Rgb(0.3f), 20)},
            {"lambert", make_phong(Rgb(0.7f))},
            {"plastic", make_plastic(Rgb(0.5f, 0.3f, 0.2f))},
            {"roughplastic", make_rough_plastic(ggx, Rgb(0.5f))},
            {"roughconductor_ggx", make_rough_conductor(ggx, *named_conductor("Au"))},
            {"roughconductor_aniso", make_rough_conductor(aniso)},
            {"roughdielectric_ggx", make_rough_dielectric(ggx, 1.5f, 1.0f)},
            {"roughdielectric_aniso", make_rough_dielectric(aniso, 1.33f, 1.1f)},
            {"dielectric", make_dielectric(1.5f)},
            {"conductor", make_conductor(*named_conductor("Cu"))}};
}

BsdfContext flat_context(TransportMode mode) {
    BsdfContext ctx;
    ctx.ng = ctx.frame.n;  // the identity frame: shading normal = geometric normal = +z
    ctx.mode = mode;
    return ctx;
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class BsdfContextTest : public ::testing::TestWithParam<Case> {};

void expect_close(const Rgb& a, const Rgb& b, const std::string& what) {
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(a[c], b[c], 2e-4f * std::max({1.0f, std::abs(a[c]), std::abs(b[c])})) << what;
}

TEST_P(BsdfContextTest, ImportanceModeIsTheAdjoint) {
    const Material& m = GetParam().material;
    const BsdfContext radiance = flat_context(TransportMode::Radiance), importance = flat_context(TransportMode::Importance);
    Sampler rng(21, 0, 0);
    int nonzero = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f wi = square_to_uniform_sphere(rng.next2d()), wo = square_to_uniform_sphere(rng.next2d());
        const Rgb adjoint = m.eval(importance, wi, wo), swapped = m.eval(radiance, wo, wi);
        expect_close(adjoint, swapped, GetParam().name + ": f*(wi, wo) vs f(wo, wi)");
        nonzero += !is_black(swapped);
        // Radiance mode with a context is the plain model, bit for bit.
        ASSERT_EQ(m.eval(radiance, wi, wo), m.eval(wi, wo));
    }
    if (!m.is_delta()) { EXPECT_GT(nonzero, 1000) << "the test must see non-zero values"; }
}

TEST_P(BsdfContextTest, SamplesCarryReversePdfsLobesAndImportanceWeights) {
    const Material& m = GetParam().material;
    BsdfContext importance = flat_context(TransportMode::Importance);
    importance.reverse_pdf = true;
    const BsdfContext radiance = flat_context(TransportMode::Radiance);
    Sampler rng(22, 0, 0);
    int samples = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f wi = square_to_uniform_sphere(rng.next2d());
        const Vec2f u = rng.next2d();
        const auto s = m.sample(importance, wi, u);
        const auto r = m.sample(radiance, wi, u);
        ASSERT_EQ(s.has_value(), r.has_value());
        if (!s) continue;
        ++samples;
        ASSERT_EQ(s->wo, r->wo);  // the mode changes weights, never directions
        ASSERT_EQ(s->lobe & m.lobes(), s->lobe) << "a sampled lobe the material does not have";
        ASSERT_EQ(s->delta, (s->lobe & kLobeSpecular) != 0);
        ASSERT_EQ((s->lobe & kLobeTransmission) != 0, wi.z * s->wo.z < 0);
        if (s->delta) {
            // The reverse probability of the same delta lobe, sampled from wo.
            float reverse = -1;
            for (float ux = 0.0005f; ux < 1; ux += 0.001f) {
                const auto back = m.sample(importance, s->wo, {ux, 0.5f});
                if (back && back->lobe == s->lobe) {
                    reverse = back->pdfW;
                    break;
                }
            }
            // Fresnel in float from either side; near grazing incidence a refracted direction
            // carries its rounding into F at about 1e-4.
            ASSERT_NEAR(s->pdf_rev, reverse, 2e-4f) << GetParam().name;
            if (s->lobe & kLobeTransmission) {
                // Importance does not scale by eta^2: the refraction weight is 1.
                const Rgb weight = s->f * (std::abs(s->wo.z) / s->pdfW);
                expect_close(weight, Rgb(1.0f), GetParam().name + " refraction weight in importance mode");
            }
        } else {
            ASSERT_EQ(s->pdf_rev, m.pdf(s->wo, wi));
            ASSERT_FLOAT_EQ(s->pdf_rev, m.pdf(importance, s->wo, wi));
            expect_close(s->f, m.eval(importance, wi, s->wo), GetParam().name + ": sampled f in importance mode");
        }
    }
    EXPECT_GT(samples, 5000);
}

INSTANTIATE_TEST_SUITE_P(Materials, BsdfContextTest, ::testing::ValuesIn(materials()),
                         [](const auto& info) { return info.param.name; });

// With a shading normal tilted away from the geometric one, the adjoint differs from the
// swapped BSDF by |wi.ns| |wo.ng| / (|wi.ng| |wo.ns|), and directions on different sides of
// the two surfaces carry nothing in importance mode.
TEST(BsdfContext, ShadingNormalCorrectionOfTheAdjoint) {
    const Material m = make_phong(Rgb(0.5f), Rgb(0.3f), 10);
    BsdfContext importance;
    importance.frame = Frame(normalize(Vec3f(0.3f, 0.1f, 1.0f)));  // the shading normal
    importance.ng = Vec3f(0, 0, 1);
    importance.mode = TransportMode::Importance;
    BsdfContext radiance = importance;
    radiance.mode = TransportMode::Radiance;
    const Vec3f ng = importance.frame.to_local(importance.ng);
    Sampler rng(23, 0, 0);
    int corrected = 0, refused = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f wi = square_to_cosine_hemisphere(rng.next2d()), wo = square_to_uniform_hemisphere(rng.next2d());
        const Rgb adjoint = m.eval(importance, wi, wo), swapped = m.eval(radiance, wo, wi);
        if (dot(wi, ng) <= 0 || dot(wo, ng) <= 0) {
            ASSERT_EQ(adjoint, Rgb(0.0f));
            ++refused;
            continue;
        }
        const float k = std::abs(wi.z * dot(wo, ng)) / std::abs(dot(wi, ng) * wo.z);
        expect_close(adjoint, swapped * k, "shading-normal correction");
        corrected += std::abs(k - 1) > 0.01f;
    }
    EXPECT_GT(corrected, 1000);
    EXPECT_GT(refused, 10);
}

}  // namespace
}  // namespace pathlab::test
