// The spot emitter (lights/spot.hpp): Mitsuba 3's falloff (full intensity inside beam_width,
// a linear ramp in angle down to 0 at cutoff_angle), its power against a numerical integral,
// the incident radiance I falloff / d^2, chi-square of its emission sampling against
// pdf_emission, its scene-file reader (defaults, placement, refusals), and the projected texture
// (Mitsuba 3's uv in the to_world's axes; a constant texture renders as a scaled intensity, bit
// for bit, by pt-mis and by bdpt's light paths).
#include <gtest/gtest.h>

#include "chi2.hpp"
#include "lights/light.hpp"
#include "render_helpers.hpp"
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
    // Mitsuba 0.6's spellings (toWorld, cutoffAngle, beamWidth), as every emitter's toWorld.
    const SceneDescription old = read(R"(<emitter type="spot"><rgb name="intensity" value="5"/>
        <float name="cutoffAngle" value="40"/><float name="beamWidth" value="10"/>
        <transform name="toWorld"><lookat origin="1, 2, 3" target="1, 2, 0" up="0, 1, 0"/></transform></emitter>
        <emitter type="point"><transform name="toWorld"><translate x="1" y="2" z="3"/></transform></emitter>)");
    const SpotLight b = std::get<SpotLight>(old.lights[0]);
    EXPECT_EQ(b.position, a.position);
    EXPECT_EQ(b.frame.n, a.frame.n);
    EXPECT_EQ(b.beam_width, a.beam_width);
    EXPECT_EQ(b.cutoff, a.cutoff);
    EXPECT_EQ(std::get<PointLight>(old.lights[1]).position, Vec3f(1, 2, 3));
    for (const char* bad : {R"(<emitter type="spot"><float name="beam_width" value="30"/></emitter>)",
                            R"(<emitter type="spot"><float name="cutoff_angle" value="0"/></emitter>)"})
        EXPECT_THROW(read(bad), SceneFileError) << bad;
}

SceneDescription read_spot_scene(const std::string& emitter) {
    return load_scene_text("<scene version=\"3.0.0\"><shape type=\"sphere\"/>" + emitter + "</scene>", "spot.xml", ".");
}

TEST(Spot, ProjectedTextureRefusals) {
    const std::string checker = R"(<texture type="checkerboard" name="texture"/>)";
    const std::pair<std::string, std::string> bad[] = {
        {R"(<emitter type="spot"><float name="cutoff_angle" value="90"/>)" + checker + "</emitter>", "below 90"},
        {R"(<emitter type="spot"><rgb name="texture" value="0.5"/>)" + checker + "</emitter>", "given twice"},
        {R"(<emitter type="spot"><texture type="checkerboard" name="pattern"/></emitter>)", "named \"texture\""},
        {R"(<emitter type="spot">)" + checker + checker + "</emitter>", "one projected texture"},
        {R"(<emitter type="spot"><bsdf type="diffuse"/></emitter>)", "only nested plugin"},
        {R"(<emitter type="point">)" + checker + "</emitter>", "no nested plugins"},
        {R"(<emitter type="spot"><texture type="checkerboard" name="texture"><rgb name="color1" value="-1"/></texture></emitter>)",
         "must not be negative"}};
    for (const auto& [text, message] : bad) {
        try {
            read_spot_scene(text);
            ADD_FAILURE() << "accepted: " << text;
        } catch (const SceneFileError& e) {
            EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << text << "\n" << e.what();
        }
    }
}

// Mitsuba 3's projection: towards the unit direction (x, y, z) of the to_world's own axes the
// texture is read at uv = 0.5 + 0.5 (x, y) / (z tan(cutoff)). The lookat below turns the spot's
// x axis to world -x (and y to world +y); the checker is not symmetric under the half turn about
// the axis that relates this frame to `frame`'s basis around the axis, so a projection in any
// frame other than the to_world's fails here.
TEST(Spot, ProjectedTextureFollowsMitsubasUvInTheToWorldAxes) {
    const SpotLight spot = std::get<SpotLight>(read_spot_scene(R"(<emitter type="spot"><rgb name="intensity" value="2"/>
        <float name="cutoff_angle" value="40"/><float name="beam_width" value="40"/>
        <texture type="checkerboard" name="texture"><rgb name="color0" value="1, 0.5, 0.25"/><rgb name="color1" value="0.125"/>
            <transform name="to_uv"><scale x="3" y="2"/><translate x="0.25"/></transform></texture>
        <transform name="to_world"><lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/></transform></emitter>)")
                                               .lights[0]);
    ASSERT_TRUE(spot.texture);
    const float t = std::tan(40 * kPi / 180);
    int compared = 0;
    for (float u = 0.03f; u < 1; u += 0.0625f)
        for (float v = 0.03f; v < 1; v += 0.0625f) {
            // The point of the floor z = 0 the spot sees at (u, v): local (x, y) = (2u - 1, 2v - 1) t.
            const Vec3f local((2 * u - 1) * t, (2 * v - 1) * t, 1.0f);
            if (local.x * local.x + local.y * local.y >= t * t) continue;  // outside the cone
            const Vec3f p(-local.x * 2, local.y * 2, 0.0f);                // world x is local -x
            const auto s = spot.sample_li(p, Vec2f(0.5f, 0.5f));
            ASSERT_TRUE(s);
            const float d2 = dot(p - spot.position, p - spot.position);
            const Rgb expected = spot.texture->eval(Vec2f(u, v)) * (2.0f / d2);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(s->Le[c], expected[c], 1e-5f * expected[c]) << u << " " << v;
            ++compared;
        }
    EXPECT_GT(compared, 100);
    // The power's factor: the beam's mean of the texture (a 3 x 2 checker of two colours over a
    // disk: close to their mean) times the untextured power.
    SpotLight plain = spot;
    plain.texture = nullptr;
    const float ratio = spot.power(kSphere) / plain.power(kSphere);
    EXPECT_NEAR(ratio, (mean(Rgb(1, 0.5f, 0.25f)) + 0.125f) / 2, 0.05f);
}

// A constant texture c is the intensity times c, bit for bit (c = 0.5 is exact in floating
// point), for camera paths (sample_li) and light paths (sample_emission, bdpt), through the
// texture plugin as through an <rgb name="texture">; and a checker projected on a floor shows
// as its pattern: the diagonal quadrants of the beam's image hold color0, the others color1.
TEST(Spot, ProjectedTexturesRender) {
    const auto scene = [](const std::string& intensity, const std::string& texture) {
        return load_scene_text(R"(<scene version="3.0.0">
            <sensor type="perspective"><float name="fov" value="70"/>
                <transform name="to_world"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
                <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film></sensor>
            <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform><bsdf type="diffuse"/></shape>
            <emitter type="spot"><rgb name="intensity" value=")" + intensity + R"("/><float name="cutoff_angle" value="35"/>)" + texture + R"(
                <transform name="to_world"><lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/></transform></emitter></scene>)",
                               "spot.xml", ".");
    };
    const SceneDescription half = scene("3, 2, 1", ""), textured = scene("6, 4, 2", R"(<rgb name="texture" value="0.5"/>)"),
                           plugin = scene("6, 4, 2", R"(<texture type="checkerboard" name="texture">
                               <rgb name="color0" value="0.5"/><rgb name="color1" value="0.5"/></texture>)");
    for (const char* algorithm : {"pt-mis", "bdpt"}) {
        const Image a = render_scene(half, algorithm, 16, 16, 4).film.mean();
        EXPECT_TRUE(bit_identical(a, render_scene(textured, algorithm, 16, 16, 4).film.mean())) << algorithm;
        EXPECT_TRUE(bit_identical(a, render_scene(plugin, algorithm, 16, 16, 4).film.mean())) << algorithm;
    }
    IntegratorOptions direct;
    direct.max_depth = 1;
    const Image checker = render_scene(scene("1", R"(<texture type="checkerboard" name="texture">
                               <rgb name="color0" value="1"/><rgb name="color1" value="0.25"/></texture>)"),
                                       "pt-mis", 16, 16, 16, 1, direct)
                              .film.mean();
    double quadrant[2][2] = {};
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) quadrant[y / 8][x / 8] += checker.at(x, y).x;
    const double diagonal = quadrant[0][0] + quadrant[1][1], other = quadrant[0][1] + quadrant[1][0];
    // The scene is symmetric under the mirrors that swap quadrants: the ratio is the colours'
    // 4, up to the pixel filter's jitter across the beam's edge.
    EXPECT_NEAR(std::max(diagonal, other) / std::min(diagonal, other), 4.0, 0.2);
}

}  // namespace
}  // namespace pathlab::test
