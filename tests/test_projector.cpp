// The projector emitter (lights/projector.hpp, Mitsuba 3's projection light): the irradiance it
// gives a plane facing it at distance 1 is pi scale E (closed form), its image is read at
// Mitsuba's camera uv in the to_world's axes with the image's aspect, its power is the integral of
// its intensity over the sphere, chi-square of its emission sampling against pdf_emission, the
// reader's fields of view and refusals, and light tracing and bdpt converge to direct-mis's image
// of a projected checkerboard (z-tests).
#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

#include "chi2.hpp"
#include "image/image_io.hpp"
#include "lights/light.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();
const SceneSphere kSphere{{0, 0, 0}, 3};

SceneDescription scene_with(const std::string& emitter, const std::string& dir = ".") {
    return load_scene_text(R"(<scene version="3.0.0">
        <sensor type="perspective"><float name="fov" value="60"/>
            <transform name="to_world"><lookat origin="0, 0, -1" target="0, 0, 1" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film></sensor>
        <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate y="1" angle="180"/><translate z="1"/></transform>
            <bsdf type="diffuse"/></shape>
        )" + emitter + "</scene>",
                           dir + "/projector.xml", dir);
}

ProjectorLight projector_of(const SceneDescription& d) { return std::get<ProjectorLight>(d.lights.at(0)); }

// At the origin looking along +z (lookat's local x is world x here), fov 60 along x.
const char* kPlain = R"(<emitter type="projector"><float name="fov" value="60"/><rgb name="irradiance" value="2"/>
    <float name="scale" value="0.5"/><transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, 1" up="0, 1, 0"/></transform></emitter>)";

TEST(Projector, AFacingPlaneAtDistanceOneReceivesPiScaleE) {
    const ProjectorLight l = projector_of(scene_with(kPlain));
    const float t = std::tan(30 * kPi / 180);
    EXPECT_NEAR(l.tan_x, t, 1e-6f);
    for (const Vec3f p : {Vec3f(0, 0, 1), Vec3f(0.9f * t, 0.3f * t, 1), Vec3f(-0.5f * t, -0.99f * t, 1)}) {
        const auto ls = l.sample_li(p, {0.5f, 0.5f});
        ASSERT_TRUE(ls);
        EXPECT_TRUE(ls->delta);
        const float cosine = std::abs(ls->wi.z);  // the plane's normal is z
        EXPECT_NEAR(ls->Le.x * cosine, kPi * 0.5f * 2, 1e-4f) << p.x << " " << p.y;
    }
    // Outside the image (the constant's aspect is 1) and behind the pinhole: nothing.
    EXPECT_FALSE(l.sample_li(Vec3f(1.01f * t, 0, 1), {0.5f, 0.5f}));
    EXPECT_FALSE(l.sample_li(Vec3f(0, -1.01f * t, 1), {0.5f, 0.5f}));
    EXPECT_FALSE(l.sample_li(Vec3f(0, 0, -1), {0.5f, 0.5f}));
}

class ProjectorImage : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = (std::filesystem::temp_directory_path() / ("pathlab-projector-" + std::to_string(::getpid()))).string();
        std::filesystem::create_directories(dir_);
        // 4 x 2 texels, each its own value: texel (x, y) holds 1 + x + 4 y.
        Image img(4, 2, Rgb(0.0f));
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x) img.at(x, y) = Rgb(float(1 + x + 4 * y));
        write_image(img, dir_ + "/slide.exr");
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::string dir_;
};

// Mitsuba's camera uv: u = 1/2 - x / (2 z tan), v = 1/2 - a y / (2 z tan), a = 4 / 2 here, in the
// to_world's axes (a lookat whose local x is world -x turns the image over).
TEST_F(ProjectorImage, ReadsTheImageAtMitsubasCameraUv) {
    for (const bool mirrored : {false, true}) {
        const std::string target = mirrored ? "0, 0, -1" : "0, 0, 1";
        const ProjectorLight l = projector_of(scene_with(R"(<emitter type="projector"><float name="fov" value="60"/>
            <texture type="bitmap" name="irradiance"><string name="filename" value="slide.exr"/><string name="filter_type" value="nearest"/></texture>
            <transform name="to_world"><lookat origin="0, 0, 0" target=")" + target + R"(" up="0, 1, 0"/></transform></emitter>)",
                                                         dir_));
        EXPECT_EQ(l.aspect, 2.0f);
        const float t = std::tan(30 * kPi / 180), z = mirrored ? -1.0f : 1.0f;
        // Local x = -t / 2 (u = 3/4: texel column 3), y = t / 4 (v = 1/4: row 0) at z = 1.
        const Vec3f local(-0.5f * t, 0.25f * t, 1);
        const Vec3f world(mirrored ? -local.x : local.x, local.y, z);  // lookat to -z: its x is world -x
        const auto ls = l.sample_li(world, {0.5f, 0.5f});
        ASSERT_TRUE(ls) << mirrored;
        const float cos3 = std::pow(1 / length(local), 3.0f);
        EXPECT_NEAR(ls->Le.x * dot(world, world), kPi * 4 / cos3, 1e-3f) << mirrored;  // texel (3, 0) holds 4
        // v = 3/4 (row 1) and u = 1/8 (column 0): local (3 t / 4, -t / 4).
        const Vec3f other(0.75f * t, -0.25f * t, 1);
        const auto lo = l.sample_li(Vec3f(mirrored ? -other.x : other.x, other.y, z), {0.5f, 0.5f});
        ASSERT_TRUE(lo);
        EXPECT_NEAR(lo->Le.x * dot(other, other), kPi * 5 / std::pow(1 / length(other), 3.0f), 1e-3f) << mirrored;  // texel (0, 1): 5
    }
}

// Its power is the integral of I over the sphere (a midpoint rule in theta and phi).
TEST_F(ProjectorImage, PowerIsTheIntegralOfItsIntensity) {
    const ProjectorLight l = projector_of(scene_with(R"(<emitter type="projector"><float name="fov" value="50"/>
        <texture type="bitmap" name="irradiance"><string name="filename" value="slide.exr"/></texture><float name="scale" value="0.3"/></emitter>)",
                                                     dir_));
    const int nt = 3000, np = 3000;
    double integral = 0;
    for (int i = 0; i < nt; ++i) {
        const double theta = 0.5 * M_PI * (i + 0.5) / nt;
        for (int j = 0; j < np; ++j) {
            const double phi = 2 * M_PI * (j + 0.5) / np;
            const Vec3f w(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
            integral += mean(l.intensity(w)) * std::sin(theta) * (0.5 * M_PI / nt) * (2 * M_PI / np);
        }
    }
    EXPECT_NEAR(l.power(kSphere), integral, 3e-3 * integral);
}

TEST(Projector, EmissionSamplingFollowsItsPdf) {
    ProjectorLight p = projector_of(scene_with(kPlain));
    p.position = Vec3f(0.3f, 0.1f, 0.2f);
    p.axes = Frame(normalize(Vec3f(0.2f, -0.4f, 1)));
    p.aspect = 1.5f;
    const Light light = p;
    double worst = 0;
    const Chi2Result r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = sample_emission(light, {0.5f, 0.5f}, u, kSphere);
            if (!s) return std::nullopt;
            const EmissionPdf e = pdf_emission(light, s->origin, s->normal, s->direction, kSphere);
            worst = std::max(worst, std::abs(double(e.pdfW) / s->pdfW - 1));
            EXPECT_EQ(s->origin, p.position);
            EXPECT_NEAR(s->Le.x, p.intensity(s->direction).x, 1e-4f * s->Le.x);
            return s->direction;
        },
        [&](const Vec3f& w) { return pdf_emission(light, p.position, w, w, kSphere).pdfW; }, p.axes.n,
        Chi2Options{.theta_bins = 36, .phi_bins = 72});
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3);
    EXPECT_LT(worst, 1e-5);
}

TEST(Projector, FieldsOfViewAndRefusals) {
    const auto tan_x = [](const std::string& params) {
        return projector_of(scene_with("<emitter type=\"projector\">" + params + "</emitter>")).tan_x;
    };
    const float t = std::tan(25 * kPi / 180);
    EXPECT_NEAR(tan_x(R"(<float name="fov" value="50"/>)"), t, 1e-6f);
    EXPECT_NEAR(tan_x(R"(<float name="fov" value="50"/><string name="fov_axis" value="diagonal"/>)"), t / std::sqrt(2.0f), 1e-6f);
    // No fov: a 50 mm lens, its film's diagonal (43.27 mm) spanned by the image's.
    EXPECT_NEAR(tan_x(""), std::sqrt(36.0f * 36 + 24 * 24) / 100 / std::sqrt(2.0f), 1e-6f);
    EXPECT_NEAR(tan_x(R"(<string name="focal_length" value="25mm"/>)"), std::sqrt(36.0f * 36 + 24 * 24) / 50 / std::sqrt(2.0f), 1e-6f);
    const auto error_of = [](const std::string& emitter) -> std::string {
        try {
            scene_with(emitter);
        } catch (const SceneFileError& e) {
            return e.what();
        }
        return "";
    };
    for (const auto& [emitter, message] : std::vector<std::pair<std::string, std::string>>{
             {R"(<emitter type="projector"><float name="fov" value="180"/></emitter>)", "fov must be between 0 and 180 degrees"},
             {R"(<emitter type="projector"><float name="fov" value="40"/><string name="fov_axis" value="z"/></emitter>)",
              "unsupported fov_axis 'z'"},
             {R"(<emitter type="projector"><string name="focal_length" value="wide"/></emitter>)", "focal_length must be a length"},
             {R"(<emitter type="projector"><rgb name="irradiance" value="1"/><texture type="checkerboard" name="irradiance"/></emitter>)",
              "irradiance is given twice"},
             {R"(<emitter type="projector"><texture type="checkerboard" name="texture"/></emitter>)",
              "a projector's image must be named \"irradiance\""},
             {R"(<emitter type="projector"><rgb name="irradiance" value="-1"/></emitter>)", "must not be negative"},
         }) {
        const std::string e = error_of(emitter);
        EXPECT_NE(e.find(message), std::string::npos) << e;
    }
}

// A checkerboard thrown on a wall: light tracing and bdpt (the projector's emission sampling and
// pdfs) converge to direct-mis's image (its incident sampling), per-pixel z-tests.
TEST(Projector, LightPathsAndLightSamplesAgree) {
    const SceneDescription d = scene_with(R"(<emitter type="projector"><float name="fov" value="40"/>
        <texture type="checkerboard" name="irradiance"><rgb name="color0" value="1"/><rgb name="color1" value="0.2"/>
            <transform name="to_uv"><scale value="3"/></transform></texture>
        <transform name="to_world"><lookat origin="0.2, 0.1, -0.5" target="0, 0, 1" up="0, 1, 0"/></transform></emitter>)");
    expect_estimators_agree(d, "direct-mis", {"lt", "bdpt"}, 16, 256);  // one wall: direct light is all the light
}

}  // namespace
}  // namespace pathlab::test
