// The envmap emitter (lights/envmap.hpp) and the piecewise-constant distributions under it
// (core/distribution.hpp): chi-square of the sampled directions against pdf() for a one-hot
// map, a smooth map and a sky with a bright sun (each turned by a to_world), the density each
// sample reports equal to pdf(), luminance weights L / pdfW within the bound the cell maxima
// promise, the texel the distribution chose found again by a lookup at the sampled direction,
// Mitsuba 3's orientation, emission from the entry disk, a constant map rendering like the
// constant emitter (z-test), and images read from files (with the bad ones refused).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "chi2.hpp"
#include "cli_runner.hpp"
#include "image/image_io.hpp"
#include "judge/image_statistics.hpp"
#include "lights/light.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();
const SceneSphere kSphere{{0.5f, -0.25f, 1.0f}, 2.5f};

Frame rotated_frame() {
    const Transform t = Transform::rotate({1, 2, 3}, 40);
    Frame f;
    f.s = Vec3f(t.vector({1, 0, 0})), f.t = Vec3f(t.vector({0, 1, 0})), f.n = Vec3f(t.vector({0, 0, 1}));
    return f;
}

// The texel (x, y) of a W x H map looks along this emitter-frame direction at its centre.
Vec3f texel_direction(int x, int y, int w, int h) { return EnvMap::uv_to_direction({(x + 0.5f) / w, (y + 0.5f) / h}); }

std::shared_ptr<const EnvMap> one_hot_map() {
    std::vector<Rgb> t(16 * 8, Rgb(0.0f));
    t[2 * 16 + 5] = Rgb(50, 40, 30);
    return std::make_shared<const EnvMap>(16, 8, std::move(t), rotated_frame());
}

std::shared_ptr<const EnvMap> smooth_map() {
    const int w = 32, h = 16;
    std::vector<Rgb> t;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Vec3f d = texel_direction(x, y, w, h);
            t.push_back(Rgb(1.2f + d.y, 1.0f + 0.6f * d.x * d.z, 0.5f + 0.4f * d.z * d.z));
        }
    return std::make_shared<const EnvMap>(w, h, std::move(t), rotated_frame());
}

// A sky (brighter towards the zenith, a dim ground) with a sun of a few texels 30000 x brighter.
std::shared_ptr<const EnvMap> sun_map() {
    const int w = 64, h = 32;
    const Vec3f sun = normalize(Vec3f(0.6f, 0.5f, -0.3f));
    std::vector<Rgb> t;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Vec3f d = texel_direction(x, y, w, h);
            if (dot(d, sun) > std::cos(5 * kPi / 180)) t.push_back(Rgb(30000, 28000, 25000));
            else t.push_back(d.y > 0 ? Rgb(0.3f, 0.5f, 1.0f) * (0.4f + d.y) : Rgb(0.1f));
        }
    return std::make_shared<const EnvMap>(w, h, std::move(t), rotated_frame());
}

// How closely pdf() can find a sample's density again: 1e-4 relative, and near the poles the
// rounding of the direction's tiny x and z components (about 1e-7 each, after the turn to the
// world and back) in sin(theta) = |(x, z)|, which the density divides by.
double pdf_tolerance(const EnvMap& map, const Vec3f& w) {
    const Vec3f l = map.frame().to_local(w);
    return 1e-4 + 1e-6 / std::sqrt(double(l.x) * l.x + double(l.z) * l.z);
}

struct MapCase {
    const char* name;
    std::shared_ptr<const EnvMap> (*make)();
};

class EnvMapSampling : public ::testing::TestWithParam<MapCase> {};

// The histogram's cells are the texels: directions in the emitter's frame around its +y, with
// as many theta and phi bins as the map has rows and columns (the harness's phi = 0 lies a
// quarter turn from the map's u = 0), so each cell's expected count is exact.
Chi2Options texel_histogram(const EnvMap& m) {
    Chi2Options o;
    o.theta_bins = m.height(), o.phi_bins = m.width();
    return o;
}

TEST_P(EnvMapSampling, DirectionsFollowPdfWithBoundedWeights) {
    const auto map = GetParam().make();
    const EnvMapLight light{map};
    // The bound the cell maxima promise, computed independently (and more loosely): 2 pi^2 times
    // the mean over the texels of (the largest luminance of the 3 x 3 texels around) x (the
    // largest sin(theta) of the row).
    const int w = map->width(), h = map->height();
    double bound = 0;
    for (int y = 0; y < h; ++y) {
        const double t0 = M_PI * y / h, t1 = M_PI * (y + 1) / h;
        const double sin_max = (t0 <= M_PI / 2 && t1 >= M_PI / 2) ? 1.0 : std::max(std::sin(t0), std::sin(t1));
        for (int x = 0; x < w; ++x) {
            double m = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    m = std::max(m, double(luminance(map->texel((x + dx + w) % w, std::clamp(y + dy, 0, h - 1)))));
            bound += m * sin_max;
        }
    }
    bound *= 2 * M_PI * M_PI / (w * h);

    double worst_pdf = 0, worst_weight = 0;
    long samples = 0, texel_mismatches = 0, near_edges = 0;
    const Chi2Result r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto ls = light.sample_li(Vec3f(0.0f), u);
            if (!ls) return std::nullopt;
            const auto s = map->sample(u);
            ++samples;
            worst_weight = std::max(worst_weight, double(luminance(ls->Le)) / ls->pdfW / bound);
            // The lookup at the sampled direction finds the texel the distribution chose, and
            // pdf() the density the sample reported (but for rounding within 1e-4 of a texel's
            // edge, where the direction may fall in the neighbour's cell).
            const float fx = s->uv.x * w - s->x, fy = s->uv.y * h - s->y;
            if (std::min({fx, 1 - fx, fy, 1 - fy}) < 1e-4f) {
                ++near_edges;
            } else {
                texel_mismatches += map->texel_of(ls->wi) != std::pair{s->x, s->y};
                worst_pdf = std::max(worst_pdf, std::abs(double(light.pdf_li(ls->wi)) / ls->pdfW - 1) / pdf_tolerance(*map, ls->wi));
            }
            return map->frame().to_local(ls->wi);
        },
        [&](const Vec3f& local) { return light.pdf_li(map->frame().to_world(local)); }, {0, 1, 0}, texel_histogram(*map));
    EXPECT_GT(r.p_value, kAlpha) << GetParam().name << ": " << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << GetParam().name;
    EXPECT_LT(worst_pdf, 1.0) << GetParam().name << ": a sample's pdfW differs from pdf_li()";
    EXPECT_LE(worst_weight, 1.0 + 1e-4) << GetParam().name << ": L / pdfW above the bound " << bound;
    EXPECT_EQ(texel_mismatches, 0) << GetParam().name;
    EXPECT_LT(near_edges, samples / 1000) << GetParam().name;
    EXPECT_EQ(r.rejected_fraction, 0.0) << GetParam().name;
}

INSTANTIATE_TEST_SUITE_P(Maps, EnvMapSampling,
                         ::testing::Values(MapCase{"one_hot", one_hot_map}, MapCase{"smooth", smooth_map}, MapCase{"sun", sun_map}),
                         [](const auto& info) { return std::string(info.param.name); });

// The test of the test: a pdf without the Jacobian's 1 / sin(theta) fails it.
TEST(EnvMapSampling, Chi2DetectsAPdfWithoutSinTheta) {
    const auto map = smooth_map();
    const EnvMapLight light{map};
    const Chi2Result r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto ls = light.sample_li(Vec3f(0.0f), u);
            return ls ? std::optional(map->frame().to_local(ls->wi)) : std::nullopt;
        },
        [&](const Vec3f& local) {
            const float sin_theta = std::sqrt(local.x * local.x + local.z * local.z);
            return light.pdf_li(map->frame().to_world(local)) * sin_theta * (kPi / 2);  // normalised, but no 1 / sin
        },
        {0, 1, 0}, texel_histogram(*map));
    EXPECT_LT(r.p_value, kAlpha) << r.describe();
}

// Mitsuba 3's orientation: the top row looks along +y, u = 0 along -z, u = 1/4 along +x, the
// middle along +z, u = 3/4 along -x; to_world turns it.
TEST(EnvMapLookup, FollowsMitsubasLatLongConvention) {
    const int w = 8, h = 4;
    std::vector<Rgb> t(w * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) t[size_t(y * w + x)] = Rgb(float(x), float(y), 1);
    const EnvMap map(w, h, t);
    // Between texels the lookup interpolates; texel (x, y) sits at u = (x + 1/2) / W (the centre of
    // its column) and v = y / (H - 1) (the first row at the zenith, the last at the nadir), as in
    // Mitsuba 3's envmap.cpp.
    EXPECT_EQ(map.lookup({(2 + 0.5f) / w, 1.0f / (h - 1)}), Rgb(2, 1, 1));
    EXPECT_EQ(map.lookup({(5 + 0.5f) / w, 0.0f}), Rgb(5, 0, 1));
    EXPECT_EQ(map.lookup({(5 + 0.5f) / w, 1.0f}), Rgb(5, float(h - 1), 1));
    EXPECT_NEAR(map.lookup({(2 + 0.5f) / w, 0.5f}).y, 0.5f * (h - 1), 1e-6f);
    EXPECT_NEAR(map.lookup({(2 + 0.5f) / w, 0.25f}).y, 0.25f * (h - 1), 1e-6f);  // texel-centred rows would give 0.5
    const auto at = [&](Vec3f d) { return map.direction_to_uv(normalize(d)); };
    EXPECT_NEAR(at({0, 1, 0}).y, 0.0f, 1e-6f);
    EXPECT_NEAR(at({0, -1, 0}).y, 1.0f, 1e-6f);
    EXPECT_NEAR(at({0, 0, -1}).x, 0.0f, 1e-6f);
    EXPECT_NEAR(at({1, 0, 0}).x, 0.25f, 1e-6f);
    EXPECT_NEAR(at({0, 0, 1}).x, 0.5f, 1e-6f);
    EXPECT_NEAR(at({-1, 0, 0}).x, 0.75f, 1e-6f);
    EXPECT_NEAR(at({1, 0, 0}).y, 0.5f, 1e-6f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Vec3f d = texel_direction(x, y, w, h);
            EXPECT_EQ(map.texel_of(d), std::pair(x, y));
            const Vec2f uv = map.direction_to_uv(d);
            EXPECT_NEAR(uv.x, (x + 0.5f) / w, 1e-5f);
            EXPECT_NEAR(uv.y, (y + 0.5f) / h, 1e-5f);
        }
    // u wraps around: halfway between the last column and the first, their average.
    EXPECT_NEAR(map.lookup({0.0f, 0.5f / h}).x, 0.5f * (w - 1), 1e-5f);
    // A to_world rotating +y to +z (as <rotate x="1" angle="90"/> does) puts the top row overhead.
    Frame f;
    f.s = {1, 0, 0}, f.t = {0, 0, 1}, f.n = {0, -1, 0};
    const EnvMap turned(w, h, t, f);
    EXPECT_EQ(turned.texel_of({0, 0, 1}).second, 0);
    EXPECT_EQ(turned.texel_of({0, 0, -1}).second, h - 1);
    EXPECT_EQ(turned.texel_of(normalize(Vec3f(1, 0, 0.1f))).first, w / 4);
}

// Emission: the directions of light paths follow the same distribution (travelling the other
// way), their density agrees with pdf_emission, and their origins lie on the entry disk.
TEST(EnvMapEmission, DirectionsFollowPdfFromTheEntryDisk) {
    const auto map = smooth_map();
    const Light light = EnvMapLight{map};
    double worst = 0;
    const Chi2Result r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = sample_emission(light, {0.3f, 0.6f}, u, kSphere);
            if (!s) return std::nullopt;
            const EmissionPdf p = pdf_emission(light, s->origin, s->normal, s->direction, kSphere);
            const auto e = map->sample(u);  // the same direction, with its texel
            const float fx = e->uv.x * map->width() - e->x, fy = e->uv.y * map->height() - e->y;
            if (std::min({fx, 1 - fx, fy, 1 - fy}) >= 1e-4f)  // away from the texels' edges (see above)
                worst = std::max(worst, std::abs(double(p.pdfW) / s->pdfW - 1) / pdf_tolerance(*map, -s->direction));
            worst = std::max(worst, std::abs(double(p.pdfA) / s->pdfA - 1) / 1e-6);
            EXPECT_NEAR(s->pdfA, 1 / (kPi * kSphere.radius * kSphere.radius), 1e-6f);
            const Vec3f rel = s->origin - kSphere.center;
            EXPECT_NEAR(dot(rel, s->direction), -kSphere.radius, 1e-4f);  // R upstream of the centre
            EXPECT_LE(length(rel - s->direction * dot(rel, s->direction)), kSphere.radius * 1.0001f);
            return map->frame().to_local(-s->direction);
        },
        [&](const Vec3f& local) { return map->pdf(map->frame().to_world(local)); }, {0, 1, 0}, texel_histogram(*map));
    EXPECT_GT(r.p_value, kAlpha) << r.describe();
    EXPECT_LT(worst, 1.0);
}

TEST(EnvMapEmission, PowerIsThatOfTheConstantEnvironmentOfItsMeanRadiance) {
    const SceneSphere s{{0, 0, 0}, 2};
    const EnvMapLight flat{std::make_shared<const EnvMap>(16, 8, std::vector<Rgb>(128, Rgb(0.5f, 1.0f, 1.5f)))};
    EXPECT_NEAR(flat.power(s), EnvironmentLight{Rgb(0.5f, 1.0f, 1.5f)}.power(s), 1e-4f * flat.power(s));
    // A map lit only in its upper half has half the power.
    std::vector<Rgb> half(128, Rgb(0.0f));
    for (int i = 0; i < 64; ++i) half[size_t(i)] = Rgb(1.0f);
    EXPECT_NEAR(EnvMapLight{std::make_shared<const EnvMap>(16, 8, half)}.power(s), 0.5f * EnvironmentLight{Rgb(1.0f)}.power(s), 1e-4f);
}

// A map of constant texels renders like the constant emitter of that radiance (course scene 6:
// the sky through the open front): the per-pixel z-test of pt-mis's images.
TEST(EnvMapRendering, AConstantMapRendersLikeTheConstantEmitter) {
    SceneDescription constant = make_builtin_scene(6), mapped = constant;
    const Rgb sky = std::get<EnvironmentLight>(constant.lights[0]).radiance;
    mapped.lights[0] = EnvMapLight{std::make_shared<const EnvMap>(8, 4, std::vector<Rgb>(32, sky), rotated_frame())};
    const RenderResult a = render_scene(constant, "pt-mis", 12, 12, 2048, 11), b = render_scene(mapped, "pt-mis", 12, 12, 2048, 12);
    const AgreementResult r = test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), {1e-3, 1e-4});
    RecordProperty("agreement", r.describe());
    EXPECT_TRUE(r.agree) << r.describe();
    // The test of the test: 2% more radiance in the map is seen.
    mapped.lights[0] = EnvMapLight{std::make_shared<const EnvMap>(8, 4, std::vector<Rgb>(32, sky * 1.02f), rotated_frame())};
    const RenderResult c = render_scene(mapped, "pt-mis", 12, 12, 2048, 12);
    EXPECT_FALSE(test_agreement(a.film.mean(), a.film.standard_error(), c.film.mean(), c.film.standard_error(), {1e-3, 1e-4}).agree);
}

// ---- files -----------------------------------------------------------------------------------

class EnvMapFiles : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() / fmt::format("pathlab-envmap-{}", ::getpid());
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    // A scene file with one envmap emitter (and a sphere), in the test's directory.
    std::string scene_with(const std::string& emitter) const {
        const std::string file = path("scene.xml");
        std::ofstream(file) << "<scene version=\"3.0.0\">\n<shape type=\"sphere\"/>\n" << emitter << "\n</scene>\n";
        return file;
    }
    std::filesystem::path dir_;
};

TEST_F(EnvMapFiles, ExrAndHdrImagesAreReadScaledAndTurned) {
    Image img(8, 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) img.at(x, y) = Rgb(float(x + 1), float(y + 1), 0.5f);
    for (const char* ext : {"exr", "hdr"}) {
        write_image(img, path(std::string("sky.") + ext));
        const SceneDescription d = load_scene_file(scene_with(fmt::format(
            R"(<emitter type="envmap"><string name="filename" value="sky.{}"/><float name="scale" value="2"/>
               <transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>)",
            ext)));
        ASSERT_EQ(d.lights.size(), 1u);
        const EnvMap& m = *std::get<EnvMapLight>(d.lights[0]).map;
        EXPECT_EQ(m.width(), 8);
        EXPECT_EQ(m.height(), 4);
        const float tolerance = std::string(ext) == "hdr" ? 0.02f : 0.0f;  // RGBE keeps about 1%
        EXPECT_NEAR(m.texel(3, 2).x, 8.0f, 8 * tolerance);
        EXPECT_NEAR(m.texel(3, 2).y, 6.0f, 6 * tolerance);
        EXPECT_EQ(m.texel_of({0, 0, 1}).second, 0) << "the top row looks along the rotated +y, +z";
    }
}

TEST_F(EnvMapFiles, BadImagesAreRefusedNamingTheFileWithExitCode2) {
    write_image(Image(8, 4, Rgb(1.0f)), path("good.exr"));
    std::ifstream in(path("good.exr"), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(path("cut.exr"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    std::ofstream(path("text.hdr")) << "not an image";
    std::ofstream(path("sky.png")) << "x";
    Image nan(4, 2, Rgb(1.0f));
    nan.at(3, 1) = Rgb(std::nanf(""), 1, 1);
    write_image(nan, path("nan.pfm"));
    const std::pair<const char*, const char*> cases[] = {
        {"missing.exr", "missing.exr"}, {"cut.exr", "cut.exr"}, {"text.hdr", "text.hdr"},
        {"sky.png", "sky.png"},         {"nan.pfm", "texel (3, 1) is NaN or infinite"}, {".", "."}};
    for (const auto& [file, needle] : cases) {
        const std::string scene = scene_with(fmt::format(R"(<emitter type="envmap"><string name="filename" value="{}"/></emitter>)", file));
        try {
            (void)load_scene_file(scene);
            ADD_FAILURE() << file << " was read";
        } catch (const SceneFileError& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
            EXPECT_GT(e.line, 0) << e.what();
        }
        const CliResult r = run({"--scene", scene, "--spp", "1", "-q", "-o", path("out.pfm")});
        EXPECT_EQ(r.code, 2) << file << ": " << r.err;
        EXPECT_TRUE(contains(r.err, needle)) << r.err;
    }
    // Two environments, and a to_world that is not a rotation.
    for (const std::string& bad :
         {std::string(R"(<emitter type="envmap"><string name="filename" value="good.exr"/></emitter><emitter type="constant"/>)"),
          std::string(R"(<emitter type="envmap"><string name="filename" value="good.exr"/>
                         <transform name="to_world"><scale x="1" y="2" z="1"/></transform></emitter>)")}) {
        EXPECT_THROW((void)load_scene_file(scene_with(bad)), SceneFileError) << bad;
    }
    EXPECT_THROW((void)load_scene_text(R"(<scene version="3.0.0"><shape type="sphere"/><emitter type="envmap">
        <string name="filename" value="good.exr"/></emitter></scene>)", "fuzz.xml", dir_.string(), {}, /*allow_files=*/false),
                 SceneFileError);
}

// ---- the distributions -------------------------------------------------------------------------

TEST(Distributions, SamplesAndPdfAgreeAndSkipEmptyCells) {
    const Distribution1D d({0.0f, 2.0f, 0.0f, 6.0f, 0.0f});
    EXPECT_DOUBLE_EQ(d.integral(), 8.0 / 5);
    for (float u = 0; u < 1; u += 1.0f / 4096) {
        float pdf;
        size_t cell;
        const float x = d.sample_continuous(u, pdf, &cell);
        ASSERT_TRUE(cell == 1 || cell == 3) << u;
        ASSERT_EQ(size_t(x * 5), cell);
        ASSERT_EQ(pdf, d.pdf(x));
        ASSERT_FLOAT_EQ(pdf, cell == 1 ? 2.0f / 1.6f : 6.0f / 1.6f);
    }
    float pmf, rest;
    EXPECT_EQ(d.sample_discrete(0.3f, pmf, &rest), 3u);
    EXPECT_FLOAT_EQ(pmf, 0.75f);
    EXPECT_NEAR(rest, (0.3f - 0.25f) / 0.75f, 1e-6f);
    // All zero: uniform.
    const Distribution1D z({0.0f, 0.0f});
    EXPECT_FLOAT_EQ(z.pdf(0.7f), 1.0f);
    // 2D: the density integrates to 1 and equals what samples report.
    const Distribution2D d2({1, 2, 0, 4, 0, 0}, 3, 2);
    double integral = 0;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 3; ++i) integral += d2.pdf({(i + 0.5f) / 3, (j + 0.5f) / 2}) / 6.0;
    EXPECT_NEAR(integral, 1.0, 1e-6);
    for (float u = 0.01f; u < 1; u += 0.05f) {
        float pdf;
        int c, r;
        const Vec2f p = d2.sample_continuous({u, 1 - u}, pdf, &c, &r);
        EXPECT_EQ(pdf, d2.pdf(p));
        EXPECT_FALSE(r == 1 && c != 0) << "row 1 has only its first cell";
    }
}

}  // namespace
}  // namespace pathlab::test
