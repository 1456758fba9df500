// The spot emitter (lights/spot.hpp): Mitsuba 3's falloff (full intensity inside beam_width,
// a linear ramp in angle down to 0 at cutoff_angle), its power against a numerical integral,
// the incident radiance I falloff / d^2, chi-square of its emission sampling against
// pdf_emission, and its scene-file reader (defaults, placement, refused texture).
#include <gtest/gtest.h>

#include "chi2.hpp"
#include "lights/light.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();
const SceneSphere kSphere{{0, 0, 0}, 3};

Vec3f at_angle(float degrees) { return {std::sin(degrees * kPi / 180), 0, std::cos(degrees * kPi / 180)}; }

TEST(Spot, FalloffIsMitsubasLinearRampInAngle) {
    const SpotLight s({0, 0, 0}, {0, 0, 1}, Rgb(2.0f), 30, 10);
    EXPECT_EQ(s.falloff(at_angle(0)), 1.0f);
    EXPECT_EQ(s.falloff(at_angle(9.9f)), 1.0f);
    EXPECT_NEAR(s.falloff(at_angle(15)), 0.75f, 1e-5f);
    EXPECT_NEAR(s.falloff(at_angle(20)), 0.5f, 1e-5f);
    EXPECT_NEAR(s.falloff(at_angle(29)), 0.05f, 1e-5f);
    EXPECT_EQ(s.falloff(at_angle(30.01f)), 0.0f);
    EXPECT_EQ(s.falloff(at_angle(120)), 0.0f);
    EXPECT_EQ(s.falloff(Vec3f(0, 0, -1)), 0.0f);
    // beam_width = cutoff_angle: a hard edge.
    const SpotLight hard({0, 0, 0}, {0, 0, 1}, Rgb(1.0f), 20, 20);
    EXPECT_EQ(hard.falloff(at_angle(19.9f)), 1.0f);
    EXPECT_EQ(hard.falloff(at_angle(20.1f)), 0.0f);
}

TEST(Spot, PowerIsTheIntegralOfTheFalloff) {
    for (const auto& [cutoff, beam] : {std::pair{30.0f, 10.0f}, {20.0f, 15.0f}, {25.0f, 25.0f}, {150.0f, 60.0f}}) {
        const SpotLight s({0, 0, 0}, {0, 0, 1}, Rgb(1, 2, 3), cutoff, beam);
        // Midpoint rule over theta (the falloff depends on theta only).
        double integral = 0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) {
            const double t = M_PI * (i + 0.5) / n;
            integral += s.falloff(Vec3f(float(std::sin(t)), 0, float(std::cos(t)))) * std::sin(t) * (M_PI / n) * 2 * M_PI;
        }
        EXPECT_NEAR(s.power(kSphere), 2 * integral, 2e-4 * integral) << cutoff << " " << beam;  // mean(I) = 2
    }
}

TEST(Spot, IncidentRadianceIsIntensityTimesFalloffOverDistanceSquared) {
    const Vec3f pos(1, 2, 3), axis = normalize(Vec3f(0, 0, -1));
    const SpotLight s(pos, axis, Rgb(4.0f), 30, 10);
    const Vec3f p = pos + normalize(Vec3f(std::tan(20 * kPi / 180), 0, -1)) * 2.0f;  // 20 degrees off the axis, 2 away
    const auto ls = s.sample_li(p, {0.5f, 0.5f});
    ASSERT_TRUE(ls);
    EXPECT_TRUE(ls->delta);
    EXPECT_NEAR(ls->Le.x, 4.0f * 0.5f / 4.0f, 1e-5f);
    EXPECT_NEAR(ls->distance, 2.0f, 1e-5f);
    EXPECT_FALSE(s.sample_li(pos + Vec3f(0, 0, 1), {0.5f, 0.5f}));  // behind it
}

TEST(Spot, EmissionSamplingFollowsItsPdf) {
    const Light light = SpotLight({0.3f, 0.1f, 0.2f}, normalize(Vec3f(0.2f, -0.4f, 1)), Rgb(3.0f), 35, 20);
    const SpotLight& spot = std::get<SpotLight>(light);
    double worst = 0;
    const Chi2Result r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = sample_emission(light, {0.5f, 0.5f}, u, kSphere);
            if (!s) return std::nullopt;
            const EmissionPdf p = pdf_emission(light, s->origin, s->normal, s->direction, kSphere);
            worst = std::max(worst, std::abs(double(p.pdfW) / s->pdfW - 1));
            EXPECT_EQ(s->origin, spot.position);
            EXPECT_EQ(s->pdfA, 1.0f);
            EXPECT_NEAR(s->Le.x, 3.0f * spot.falloff_world(s->direction), 1e-5f);
            return s->direction;
        },
        [&](const Vec3f& w) { return pdf_emission(light, spot.position, w, w, kSphere).pdfW; }, spot.frame.n,
        Chi2Options{.theta_bins = 36, .phi_bins = 72});  // bins of 5 degrees: the cone's edge (35) is one
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    EXPECT_LT(worst, 1e-6);
}

TEST(Spot, SceneFileReaderTakesMitsubasParameters) {
    const auto read = [](const std::string& emitter) {
        return load_scene_text("<scene version=\"3.0.0\"><shape type=\"sphere\"/>" + emitter + "</scene>", "spot.xml", ".");
    };
    const SpotLight d = std::get<SpotLight>(read(R"(<emitter type="spot"/>)").lights[0]);
    EXPECT_NEAR(d.cutoff, 20 * kPi / 180, 1e-6f);
    EXPECT_NEAR(d.beam_width, 15 * kPi / 180, 1e-6f);  // 3/4 of the cutoff
    EXPECT_EQ(d.intensity, Rgb(1.0f));
    EXPECT_EQ(d.position, Vec3f(0.0f));
    EXPECT_NEAR(d.frame.n.z, 1.0f, 1e-6f);
    const SpotLight a = std::get<SpotLight>(read(R"(<emitter type="spot"><rgb name="intensity" value="5"/>
        <float name="cutoff_angle" value="40"/><float name="beam_width" value="10"/>
        <transform name="to_world"><lookat origin="1, 2, 3" target="1, 2, 0" up="0, 1, 0"/></transform></emitter>)")
                                         .lights[0]);
    EXPECT_EQ(a.position, Vec3f(1, 2, 3));
    EXPECT_NEAR(a.frame.n.z, -1.0f, 1e-6f);
    EXPECT_NEAR(a.beam_width, 10 * kPi / 180, 1e-6f);
    for (const char* bad : {R"(<emitter type="spot"><float name="beam_width" value="30"/></emitter>)",
                            R"(<emitter type="spot"><float name="cutoff_angle" value="0"/></emitter>)"})
        EXPECT_THROW(read(bad), SceneFileError) << bad;
    try {
        read(R"(<emitter type="spot"><texture type="bitmap" name="texture"><string name="filename" value="a.png"/></texture></emitter>)");
        ADD_FAILURE() << "a texture was accepted";
    } catch (const SceneFileError& e) {
        EXPECT_NE(std::string(e.what()).find("not supported yet"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace pathlab::test
