// The image-judging tools: compare's statistics, the false-colour map, check's verdict (a
// correct noisy render passes, a biased one fails), reference sets, the HTML report (and, where
// Chromium is installed, that it loads in a browser without console errors), and bad input.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "biased_estimators.hpp"
#include "cli_runner.hpp"
#include "image/image_io.hpp"
#include "render_helpers.hpp"
#include "judge/check.hpp"
#include "judge/false_colour.hpp"
#include "judge/image_compare.hpp"
#include "judge/reference_set.hpp"
#include "judge/svg_plot.hpp"

namespace pathlab::test {
namespace {
namespace fs = std::filesystem;

std::string read_text(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

class Tools : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / fmt::format("pathlab-tools-{}-{}", ::getpid(),
                                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

// ---- compare -------------------------------------------------------------------------------

// Two 2x1 images whose differences are worked out by hand in the test.
std::pair<Image, Image> two_pixel_images() {
    Image a(2, 1), b(2, 1);
    a[0] = Rgb(1, 0, 2), a[1] = Rgb(3, 0, 2);
    b[0] = Rgb(0, 0, 1), b[1] = Rgb(1, 0, 4);
    return {a, b};
}

TEST(ToolsCompare, StatisticsOfKnownDifferences) {
    const auto [a, b] = two_pixel_images();
    const ImageDifference d = compare_images(a, b);
    const double eps = kRelMseEpsilon;
    // R: differences 1 and 2 (reference 0 and 1).
    EXPECT_DOUBLE_EQ(d.channel[0].mean_diff, 1.5);
    EXPECT_DOUBLE_EQ(d.channel[0].mae, 1.5);
    EXPECT_DOUBLE_EQ(d.channel[0].rmse, std::sqrt(2.5));
    EXPECT_DOUBLE_EQ(d.channel[0].relmse, (1 / (0 + eps) + 4 / (1 + eps)) / 2);
    EXPECT_DOUBLE_EQ(d.channel[0].max_abs_diff, 2);
    // G: equal.
    EXPECT_EQ(d.channel[1].mean_diff, 0);
    EXPECT_EQ(d.channel[1].rmse, 0);
    // B: differences +1 and -2 (reference 1 and 4): the signed mean cancels, the others do not.
    EXPECT_DOUBLE_EQ(d.channel[2].mean_diff, -0.5);
    EXPECT_DOUBLE_EQ(d.channel[2].mae, 1.5);
    EXPECT_DOUBLE_EQ(d.channel[2].relmse, (1 / (1 + eps) + 4 / (16 + eps)) / 2);
    EXPECT_DOUBLE_EQ(d.channel[2].max_abs_diff, 2);
    // All six pixel-channels: differences 1, 2, 0, 0, 1, -2.
    EXPECT_DOUBLE_EQ(d.all.mean_diff, 2.0 / 6);
    EXPECT_DOUBLE_EQ(d.all.mae, 6.0 / 6);
    EXPECT_DOUBLE_EQ(d.all.rmse, std::sqrt(10.0 / 6));
    EXPECT_DOUBLE_EQ(d.worst_mean_diff(), 1.5);
    EXPECT_EQ(d.compared, 6);
    EXPECT_EQ(d.non_finite(), 0);
}

TEST(ToolsCompare, ConstantOffsetAndIdenticalImages) {
    Image a(17, 9), b(17, 9);
    for (size_t i = 0; i < a.pixel_count(); ++i) {
        b[i] = Rgb(0.1f * float(i % 7), 0.5f, 2.0f);
        a[i] = b[i] + Rgb(0.25f, -0.125f, 0.0f);  // exact in binary
    }
    const ImageDifference d = compare_images(a, b);
    EXPECT_NEAR(d.channel[0].mean_diff, 0.25, 1e-6);
    EXPECT_NEAR(d.channel[0].rmse, 0.25, 1e-6);
    EXPECT_NEAR(d.channel[1].mean_diff, -0.125, 1e-6);
    EXPECT_NEAR(d.channel[1].mae, 0.125, 1e-6);
    EXPECT_EQ(d.channel[2].max_abs_diff, 0);
    const ImageDifference same = compare_images(b, b);
    EXPECT_EQ(same.all.rmse, 0);
    EXPECT_EQ(same.all.relmse, 0);
    EXPECT_EQ(same.all.max_abs_diff, 0);
}

TEST(ToolsCompare, NonFinitePixelsAreCountedAndLeftOut) {
    auto [a, b] = two_pixel_images();
    a[1].x = NAN;
    b[0].z = INFINITY;
    b[1].y = -INFINITY;
    const ImageDifference d = compare_images(a, b);
    EXPECT_EQ(d.nan_a, 1);
    EXPECT_EQ(d.inf_b, 2);
    EXPECT_EQ(d.compared, 3);
    EXPECT_DOUBLE_EQ(d.channel[0].mean_diff, 1.0);  // only the first pixel's R
    EXPECT_DOUBLE_EQ(d.channel[2].mean_diff, -2.0);  // only the second pixel's B
}

TEST(ToolsCompare, DifferentSizesAreAClearError) {
    try {
        compare_images(Image(4, 3), Image(3, 4));
        FAIL() << "no error";
    } catch (const ImageSizeMismatch& e) {
        EXPECT_TRUE(contains(e.what(), "4x3")) << e.what();
        EXPECT_TRUE(contains(e.what(), "3x4")) << e.what();
    }
}

TEST(ToolsCompare, RmseAgainstANoisyReferenceRemovesItsNoise) {
    Image img(10, 10, Rgb(1.0f)), ref(10, 10, Rgb(1.5f)), se(10, 10, Rgb(0.3f));
    // mean squared difference 0.25, reference noise 0.09: sqrt(0.16) = 0.4.
    EXPECT_NEAR(rmse_against_reference(img, ref, se), 0.4, 1e-6);
    EXPECT_NEAR(rmse_against_reference(img, ref), 0.5, 1e-6);
}

// ---- false colour --------------------------------------------------------------------------

TEST(ToolsFalseColour, SignedDifferencesMapToBlueGreyRed) {
    Image a(4, 1), b(4, 1, Rgb(1.0f));
    a[0] = Rgb(1.0f);            // equal: the map's grey
    a[1] = Rgb(3.0f);            // +2, beyond the scale: saturated red
    a[2] = Rgb(0.0f);            // -1 = -scale: the blue end
    a[3] = Rgb(NAN, 1.0f, 1.0f);  // non-finite: green
    const Image8 img = false_colour_difference(a, b, 1.0);
    const auto px = [&](int x) { return std::array<int, 3>{img.at(x, 0, 0), img.at(x, 0, 1), img.at(x, 0, 2)}; };
    EXPECT_EQ(px(0), (std::array<int, 3>{221, 221, 221}));
    EXPECT_EQ(px(1), (std::array<int, 3>{180, 4, 38}));
    EXPECT_EQ(px(2), (std::array<int, 3>{59, 76, 192}));
    EXPECT_EQ(px(3), (std::array<int, 3>{0, 255, 0}));
    // Halfway up the positive side is lighter and redder than halfway down the negative side.
    const auto up = diverging_colour(0.5), down = diverging_colour(-0.5);
    EXPECT_GT(up[0], up[2]);
    EXPECT_GT(down[2], down[0]);
    EXPECT_THROW(false_colour_difference(a, Image(3, 1), 1.0), ImageSizeMismatch);
}

TEST(ToolsFalseColour, AutomaticScaleIsARobustQuantile) {
    Image a(1000, 1), b(1000, 1);
    for (int x = 0; x < 1000; ++x) a.at(x, 0) = Rgb(float(x + 1) * 0.001f);  // |diff| 0.001 .. 1.000
    a.at(999, 0) = Rgb(1000.0f);                                             // a firefly
    EXPECT_NEAR(difference_scale(a, b, 0.5), 0.501, 1e-4);
    EXPECT_LT(difference_scale(a, b), 1.01);  // the firefly does not set the scale
    EXPECT_EQ(difference_scale(b, b), 1.0);   // equal images: a harmless default
}

// ---- check: the verdict --------------------------------------------------------------------

constexpr int kCheckSize = 48;

// A direct-illumination reference of scene 2 (ceiling light): direct-mis at many samples.
const RenderResult& direct_reference() {
    static const RenderResult ref = render_scene(make_builtin_scene(2), "direct-mis", kCheckSize, kCheckSize, 1024, 77);
    return ref;
}

LinearCheck check_render(const RenderResult& r) {
    const RenderResult& ref = direct_reference();
    return check_against_linear_reference(r.film.mean(), r.film.standard_error(), ref.film.mean(), ref.film.standard_error());
}

TEST(ToolsCheck, CorrectNoisyRendersPass) {
    // Three estimators, few samples: noisy, but unbiased.
    for (const char* algorithm : {"direct-light", "direct-cosine", "direct-mis"}) {
        const RenderResult r = render_scene(make_builtin_scene(2), algorithm, kCheckSize, kCheckSize, 8, 5);
        const LinearCheck c = check_render(r);
        EXPECT_TRUE(c.passes()) << algorithm << ": " << c.describe();
    }
}

TEST(ToolsCheck, RenderWithoutTheReceiverCosineFails) {
    const auto scene = Scene::build(make_builtin_scene(2));
    RenderSettings rs;
    rs.width = rs.height = kCheckSize;
    rs.spp = 8;
    rs.seed = 5;
    const RenderResult r = render(*scene, DirectLightWithoutCosine(), rs);
    const LinearCheck c = check_render(r);
    EXPECT_FALSE(c.passes()) << c.describe();
}

// A subtle bias needs more samples to be seen: at 48x48 and 128 spp the standard error of the
// image mean is about 0.6% (light sampling of the ceiling is noisy), so a light 5% too bright
// stands about 8 standard errors out (2% would be 3.4, at the edge of the 3.6 limit).
TEST(ToolsCheck, LightFivePercentTooBrightFails) {
    SceneDescription d = make_builtin_scene(2);
    for (MeshDesc& m : d.meshes)
        if (!is_black(m.emission)) m.emission *= 1.05f;
    const LinearCheck c = check_render(render_scene(d, "direct-light", kCheckSize, kCheckSize, 128, 5));
    EXPECT_FALSE(c.passes()) << c.describe();
}

// Against the course's 8-bit references (512x512): a correct render at 16 spp, far too noisy
// for the course's fixed "mean |difference| below 1 grey level" (it is 2.9 levels), passes
// because the noise explains that; the dropped cosine fails at the same sample count.
ReferenceFile course_png(int scene) {
    return {shared_dir() + "/npgr010-refs/direct/" + std::to_string(scene) + ".png", ReferenceKind::Course8bit, {}};
}

TEST(ToolsCheck, CoursePngVerdictPassesANoisyCorrectRender) {
    const RenderResult r = render_scene(make_builtin_scene(7), "direct-light", 512, 512, 16, 1234);
    const SceneVerdict v = judge_render(r.film.mean(), r.film.standard_error(), course_png(7));
    EXPECT_STREQ(verdict_name(v.verdict), "OK") << v.detail;
}

TEST(ToolsCheck, CoursePngVerdictFailsWithoutTheReceiverCosine) {
    const auto scene = Scene::build(make_builtin_scene(0));
    RenderSettings rs;
    rs.spp = 16;
    rs.seed = 1234;
    const RenderResult r = render(*scene, DirectLightWithoutCosine(), rs);
    const SceneVerdict v = judge_render(r.film.mean(), r.film.standard_error(), course_png(0));
    EXPECT_STREQ(verdict_name(v.verdict), "FAIL") << v.detail;
}

TEST(ToolsCheck, ZeroVarianceMeansExactAgreementIsRequired) {
    const Image a(3, 3, Rgb(0.5f)), zero(3, 3);
    EXPECT_TRUE(check_against_linear_reference(a, zero, a).passes());
    EXPECT_FALSE(check_against_linear_reference(a, zero, Image(3, 3, Rgb(0.50001f))).passes());
}

// ---- reference sets and file names ----------------------------------------------------------

TEST_F(Tools, FindsReferencesByTheDocumentedNamesAndTheCoursePngs) {
    const std::string course = shared_dir() + "/npgr010-refs/direct";
    const auto png = find_reference(course, 3, {});
    ASSERT_TRUE(png);
    EXPECT_EQ(fs::path(png->path).filename(), "3.png");
    EXPECT_EQ(png->kind, ReferenceKind::Course8bit);

    write_image(Image(2, 2), path("ws_c_sdwd.pfm"));  // scene 2 by the course acronym
    write_image(Image(2, 2), path("4-box-diffuse.exr"));
    write_image(Image(2, 2), path("4-box-diffuse.stderr.exr"));
    write_image(Image(2, 2), path("4.png"));  // a linear file wins over a PNG
    const auto by_acronym = find_reference(dir_.string(), 2, {});
    ASSERT_TRUE(by_acronym);
    EXPECT_EQ(fs::path(by_acronym->path).filename(), "ws_c_sdwd.pfm");
    EXPECT_TRUE(by_acronym->stderr_path.empty());
    const auto pathlab_set = find_reference(dir_.string(), 4, {});
    ASSERT_TRUE(pathlab_set);
    EXPECT_EQ(fs::path(pathlab_set->path).filename(), "4-box-diffuse.exr");
    EXPECT_EQ(fs::path(pathlab_set->stderr_path).filename(), "4-box-diffuse.stderr.exr");
    std::string tried;
    EXPECT_FALSE(find_reference(dir_.string(), 6, {}, &tried));
    EXPECT_TRUE(contains(tried, "6-env-diffuse.exr")) << tried;
}

TEST_F(Tools, MappingFileNamesReferencesAndReportsErrorsWithLineNumbers) {
    std::ofstream(path("map.txt")) << "# my files\n0 = point.hdr\n\n  ceiling-glossy=sub/glossy.pfm   # comment\n";
    const auto mapping = read_reference_mapping(path("map.txt"));
    EXPECT_EQ(mapping.size(), 2u);
    EXPECT_EQ(mapping.at(0), "point.hdr");
    EXPECT_EQ(mapping.at(3), "sub/glossy.pfm");
    write_image(Image(2, 2), path("sub/glossy.pfm"));
    const auto found = find_reference(dir_.string(), 3, mapping);
    ASSERT_TRUE(found);
    EXPECT_EQ(found->path, path("sub/glossy.pfm"));
    EXPECT_FALSE(find_reference(dir_.string(), 0, mapping));  // mapped, but not there

    std::ofstream(path("bad1.txt")) << "0 = a.exr\nkitchen = b.exr\n";
    std::ofstream(path("bad2.txt")) << "0 a.exr\n";
    std::ofstream(path("bad3.txt")) << "1 = a.exr\npoint-glossy = b.exr\n";
    const auto error_of = [&](const std::string& file) {
        try {
            read_reference_mapping(path(file));
        } catch (const ReferenceMappingError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_TRUE(contains(error_of("bad1.txt"), "bad1.txt:2: unknown scene 'kitchen'")) << error_of("bad1.txt");
    EXPECT_TRUE(contains(error_of("bad2.txt"), "bad2.txt:1: expected 'scene = file'")) << error_of("bad2.txt");
    EXPECT_TRUE(contains(error_of("bad3.txt"), "bad3.txt:2: scene 'point-glossy' is mapped twice")) << error_of("bad3.txt");
    EXPECT_TRUE(contains(error_of("none.txt"), "none.txt: cannot read")) << error_of("none.txt");
}

// ---- the command line: reference + check --------------------------------------------------

TEST_F(Tools, ReferenceThenCheckReportsOkMissingAndBlackByDesign) {
    CliResult r = run({"reference", "--out", path("refs"), "--scene", "0,2", "--algorithm", "direct-mis", "--resolution", "24x20",
                       "--spp", "512", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* f : {"0-point-diffuse.exr", "0-point-diffuse.stderr.exr", "0-point-diffuse.png", "2-ceiling-diffuse.exr"})
        EXPECT_TRUE(fs::exists(path(std::string("refs/") + f))) << f;
    const auto manifest = nlohmann::json::parse(std::ifstream(path("refs/manifest.json")));
    EXPECT_EQ(manifest["pathlab_version"], PATHLAB_VERSION);
    ASSERT_EQ(manifest["scenes"].size(), 2u);
    const nlohmann::json& e = manifest["scenes"][1];
    EXPECT_EQ(e["scene"], "ceiling-diffuse");
    EXPECT_EQ(e["algorithm"], "direct-mis");
    EXPECT_EQ(e["spp"], 512);
    EXPECT_EQ(e["seed"], 4321);
    EXPECT_GT(e["seconds"].get<double>(), 0);
    EXPECT_EQ(read_image(path("refs/2-ceiling-diffuse.exr")).width(), 24);

    // direct-light: both scenes OK (at the references' resolution), the others MISSING; exit 0.
    r = run({"check", "-a", "1", "--references", path("refs"), "--spp", "16", "--json", path("check.json")});
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("0 point-diffuse +OK "))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("2 ceiling-diffuse +OK "))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("5 box-glossy +MISSING "))) << r.out;
    const auto verdicts = nlohmann::json::parse(std::ifstream(path("check.json")));
    EXPECT_TRUE(verdicts["passed"].get<bool>());
    EXPECT_EQ(verdicts["scenes"].size(), 8u);

    // direct-cosine cannot see the point light of scene 0: black by design, not a failure.
    r = run({"check", "-a", "2b", "--references", path("refs"), "--scene", "0,2", "--spp", "16"});
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("0 point-diffuse +BLACK-BY-DESIGN "))) << r.out;

    // pt-mis (global illumination) against direct-illumination references: refused by the
    // manifest (exit 2) before rendering.
    r = run({"check", "-a", "pt-mis", "--references", path("refs"), "--scene", "2", "--spp", "16"});
    EXPECT_EQ(r.code, 2) << r.out << r.err;
    EXPECT_TRUE(contains(r.err, "rendered with direct-mis (direct illumination)")) << r.err;
    // Without the manifest, nothing says what the references are of: judged, biased, FAIL (exit 1).
    fs::rename(path("refs/manifest.json"), path("manifest.json"));
    r = run({"check", "-a", "pt-mis", "--references", path("refs"), "--scene", "2", "--spp", "16"});
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("2 ceiling-diffuse +FAIL "))) << r.out;
    fs::rename(path("manifest.json"), path("refs/manifest.json"));
    // A corrupt manifest is refused (exit 2), naming it: ignored, it let that FAIL pass unseen as
    // PASSED references of another estimator. `reference` leaves it as it is.
    const std::string good = read_text(path("refs/manifest.json"));
    for (const std::string& bad : {std::string("{\"scenes\": [ {\"file\": \"2-ceiling-diffuse.exr\","), std::string("[1, 2]"),
                                   std::string("{\"scenes\": {}}"), std::string("{\"scenes\": [{\"file\": \"2-ceiling-diffuse.exr\", \"resolution\": [\"a\", 2]}]}"),
                                   std::string("{\"scenes\": [{\"file\": \"2-ceiling-diffuse.exr\", \"resolution\": \"x\"}]}"),
                                   std::string("{\"scenes\": [{\"file\": \"2-ceiling-diffuse.exr\", \"resolution\": [16]}]}"),
                                   std::string("{\"scenes\": [{\"file\": \"2-ceiling-diffuse.exr\", \"spp\": -5}]}"),
                                   std::string("{\"scenes\": [{\"file\": \"2-ceiling-diffuse.exr\", \"algorithm\": 3}]}")}) {
        std::ofstream(path("refs/manifest.json")) << bad;
        r = run({"check", "-a", "pt-mis", "--references", path("refs"), "--scene", "2", "--spp", "16"});
        EXPECT_EQ(r.code, 2) << bad << ": " << r.out << r.err;
        EXPECT_TRUE(contains(r.err, path("refs/manifest.json") + ": ")) << r.err;
        EXPECT_FALSE(contains(r.out, "PASSED")) << r.out;
        r = run({"reference", "--out", path("refs"), "--scene", "2", "--algorithm", "direct-mis", "--resolution", "24x20", "--spp", "4", "-q"});
        EXPECT_EQ(r.code, 2) << bad;
        EXPECT_TRUE(contains(r.err, path("refs/manifest.json") + ": ")) << r.err;
        EXPECT_EQ(read_text(path("refs/manifest.json")), bad);
    }
    std::ofstream(path("refs/manifest.json")) << good;

    // A reference of another size: refused (exit 2), naming both sizes.
    r = run({"check", "-a", "1", "--references", path("refs"), "--scene", "2", "--spp", "4", "--resolution", "12x10"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "is 24x20, but --resolution asks for 12x10")) << r.err;

    // An unreadable reference: an error naming the file, without rendering.
    std::ofstream(path("refs/6-env-diffuse.exr")) << "not an EXR";
    r = run({"check", "-a", "1", "--references", path("refs"), "--scene", "6", "--spp", "4"});
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(std::regex_search(r.out, std::regex("6 env-diffuse +ERROR +6-env-diffuse.exr +.*6-env-diffuse.exr: cannot read"))) << r.out;
}

// Two renders of different scenes (their EXRs carry the scene's name and hash): compare warns,
// and with --strict refuses (exit 2); renders of one scene, and images without the metadata, pass quietly
// (with --strict, an image without it is refused: nothing shows it renders the same scene).
TEST_F(Tools, CompareWarnsOfRendersOfDifferentScenes) {
    for (const char* s : {"2", "3"})
        ASSERT_EQ(run({"-s", s, "--resolution", "8x8", "--spp", "1", "-q", "-o", path(std::string("r") + s + ".exr")}).code, 0);
    ASSERT_EQ(run({"-s", "2", "--resolution", "8x8", "--spp", "1", "--seed", "9", "-q", "-o", path("r2b.exr")}).code, 0);
    CliResult r = run({"compare", path("r2.exr"), path("r3.exr")});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "warning: " + path("r2.exr") + " is a render of ceiling-diffuse (")) << r.err;
    EXPECT_TRUE(contains(r.err, "images of different scenes")) << r.err;
    r = run({"compare", path("r2.exr"), path("r3.exr"), "--strict"});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "images of different scenes (--strict)")) << r.err;
    r = run({"compare", path("r2.exr"), path("r2b.exr"), "--strict"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(contains(r.err, "warning")) << r.err;
    // An image that does not say its scene: quietly compared, but --strict refuses it.
    ASSERT_EQ(run({"convert", path("r3.exr"), path("r3.pfm")}).code, 0);
    r = run({"compare", path("r2.exr"), path("r3.pfm")});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(contains(r.err, "warning")) << r.err;
    r = run({"compare", path("r2.exr"), path("r3.pfm"), "--strict"});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, path("r3.pfm") + " does not say which scene it renders")) << r.err;
}

TEST_F(Tools, CheckUsageErrors) {
    CliResult r = run({"check", "-a", "1", "--references", path("nowhere")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "nowhere: no such directory")) << r.err;
    r = run({"check", "-a", "bdpt-magic", "--references", dir_.string()});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "unknown algorithm 'bdpt-magic'")) << r.err;
    std::ofstream(path("map.txt")) << "9 = x.exr\n";
    r = run({"check", "-a", "1", "--references", dir_.string(), "--mapping", path("map.txt")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "map.txt:1: unknown scene '9'")) << r.err;
    r = run({"check", "-a", "1", "--references", dir_.string(), "--spp", "0"});
    EXPECT_EQ(r.code, 2);
    // No reference at all: nothing was compared, which is not a pass.
    r = run({"check", "-a", "1", "--references", dir_.string(), "--scene", "2", "--spp", "1"});
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(contains(r.out, "MISSING")) << r.out;
}

// ---- the command line: compare --------------------------------------------------------------

TEST_F(Tools, CompareCommandPrintsStatisticsJsonThresholdAndDiff) {
    const auto [a, b] = two_pixel_images();
    write_image(a, path("a.exr"));
    write_image(b, path("b.pfm"));
    CliResult r = run({"compare", path("a.exr"), path("b.pfm")});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "mean diff (A - B)")) << r.out;
    EXPECT_TRUE(contains(r.out, "RMSE")) << r.out;

    r = run({"compare", path("a.exr"), path("b.pfm"), "--json", "--threshold", "2", "--diff", path("d.png"), "--diff-scale", "4"});
    EXPECT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_DOUBLE_EQ(j["channels"][0]["mean_diff"].get<double>(), 1.5);
    EXPECT_DOUBLE_EQ(j["channels"][2]["mean_diff"].get<double>(), -0.5);
    EXPECT_TRUE(j["threshold"]["pass"].get<bool>());
    EXPECT_EQ(j["diff"]["scale"], 4.0);
    const Image8 diff = read_png8(path("d.png"));
    EXPECT_EQ(diff.width, 2);
    EXPECT_GT(diff.at(0, 0, 0), diff.at(0, 0, 2));  // A brighter in pixel 0: red side

    // The grader's measure (worst channel |mean difference| 1.5) against a threshold: exit 1.
    r = run({"compare", path("a.exr"), path("b.pfm"), "--threshold", "1"});
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(contains(r.out, "FAIL: mean = 1.5 > threshold 1")) << r.out;
    r = run({"compare", path("a.exr"), path("b.pfm"), "--threshold", "1.6", "--metric", "rmse"});  // sqrt(10/6) = 1.29
    EXPECT_EQ(r.code, 0) << r.out;
}

TEST_F(Tools, CompareBadInputIsNamed) {
    write_image(Image(4, 3), path("a.exr"));
    write_image(Image(3, 4), path("b.hdr"));
    std::ofstream(path("junk.pfm")) << "this is not an image";
    CliResult r = run({"compare", path("a.exr"), path("missing.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, path("missing.exr") + ": no such file")) << r.err;
    r = run({"compare", path("junk.pfm"), path("a.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, path("junk.pfm"))) << r.err;
    r = run({"compare", path("a.exr"), path("b.hdr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "a.exr is 4x3 but " + path("b.hdr") + " is 3x4")) << r.err;
    r = run({"compare", path("a.exr"), path("a.exr"), "--colour"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--colour")) << r.err;
    EXPECT_TRUE(contains(r.err, "Valid options of compare")) << r.err;
    EXPECT_TRUE(contains(r.err, "--threshold")) << r.err;
    r = run({"compare", path("a.exr"), path("a.exr"), "--metric", "psnr", "--threshold", "1"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "unknown --metric 'psnr'")) << r.err;
    r = run({"compare", path("a.exr")});
    EXPECT_EQ(r.code, 2);
}

// ---- the report -----------------------------------------------------------------------------

// Every src="..." of an HTML file, relative to its directory.
std::vector<std::string> image_sources(const std::string& html) {
    std::vector<std::string> out;
    const std::regex src("src=\"([^\"]+)\"");
    for (auto it = std::sregex_iterator(html.begin(), html.end(), src); it != std::sregex_iterator(); ++it) out.push_back((*it)[1]);
    return out;
}

long count(const std::string& s, const std::string& needle) {
    long n = 0;
    for (size_t p = s.find(needle); p != std::string::npos; p = s.find(needle, p + 1)) ++n;
    return n;
}

// One small report for the tests that read it.
class ToolsReport : public Tools {
protected:
    void make_report() {
        const CliResult r = run({"report", "--scene", "2", "--algorithms", "direct-light,direct-mis", "--spp", "8",
                                 "--resolution", "32x24", "--reference-spp", "64", "-q", "-o", path("out/report.html")});
        ASSERT_EQ(r.code, 0) << r.err;
        html_ = read_text(path("out/report.html"));
    }
    std::string html_;
};

TEST_F(ToolsReport, WritesValidHtmlWhoseImagesExist) {
    make_report();
    EXPECT_EQ(html_.rfind("<!DOCTYPE html>", 0), 0u);
    // Every element opened is closed (the page has no void elements but img, input, meta, link, br).
    for (const char* tag : {"html", "head", "body", "figure", "figcaption", "div", "table", "tr", "td", "svg", "script", "style", "p", "h2"})
        EXPECT_EQ(count(html_, fmt::format("<{}>", tag)) + count(html_, fmt::format("<{} ", tag)), count(html_, fmt::format("</{}>", tag)))
            << tag;
    // Images: the reference and both renders (all exposures through data-stem), both error images.
    const std::vector<std::string> sources = image_sources(html_);
    EXPECT_GE(sources.size(), 6u);
    for (const std::string& s : sources) {
        if (s.rfind("data:", 0) == 0) continue;
        EXPECT_TRUE(fs::exists(path("out/" + s))) << s;
    }
    const std::regex stem("data-stem=\"([^\"]+)\"");
    int stems = 0;
    for (auto it = std::sregex_iterator(html_.begin(), html_.end(), stem); it != std::sregex_iterator(); ++it, ++stems)
        for (const char* e : {"m4", "m1", "0", "p1", "p4"}) EXPECT_TRUE(fs::exists(path("out/" + std::string((*it)[1]) + "_e" + e + ".png"))) << (*it)[1];
    EXPECT_EQ(stems, 3);
    // Offline: nothing fetched from the network (the SVG namespace is a name, not a fetch).
    std::string without_ns = std::regex_replace(html_, std::regex("xmlns=\"http://www.w3.org/2000/svg\""), "");
    EXPECT_FALSE(contains(without_ns, "http://")) << "network reference";
    EXPECT_FALSE(contains(without_ns, "https://")) << "network reference";
    EXPECT_FALSE(contains(without_ns, "//fonts")) << "network font";
    // Pixel-level zoom, the exposure control, the statistics and a curve per algorithm.
    EXPECT_TRUE(contains(html_, "image-rendering: pixelated"));
    EXPECT_TRUE(contains(html_, "id=\"exposure\""));
    EXPECT_TRUE(contains(html_, "rendered here with pt-mis --max-depth 1"));  // the reference, said so
    EXPECT_TRUE(contains(html_, "<td>direct-mis</td>"));
    EXPECT_EQ(count(html_, "<polyline"), 4);  // each algorithm over time and over samples
    EXPECT_TRUE(fs::exists(path("out/report_files/reference.exr")));
    EXPECT_TRUE(fs::exists(path("out/report_files/convergence.svg")));
}

// A scene file too: the specular-diffuse-specular scene with bdpt and the photon methods, one
// curve each; the scene file is named in the title.
TEST_F(Tools, ReportsOnASceneFileWithThePhotonMethods) {
    const std::string scene = std::string(PATHLAB_SOURCE_DIR) + "/scenes/sds-caustic.xml";
    const CliResult r = run({"report", "--scene", scene, "--algorithms", "bdpt,sppm,vcm", "--spp", "4", "--resolution", "32x24",
                             "--reference-spp", "16", "--reference-algorithm", "vcm", "-q", "-o", path("out/sds.html")});
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string html = read_text(path("out/sds.html"));
    EXPECT_TRUE(contains(html, "sds-caustic (" + scene + ")"));
    EXPECT_TRUE(contains(html, "rendered here with vcm at 16 spp"));
    EXPECT_TRUE(contains(html, "<td>vcm</td>"));
    EXPECT_EQ(count(html, "<polyline"), 6);
    const CliResult all = run({"report", "--scene", "all", "--algorithms", "vcm", "--spp", "4", "-o", path("out/all.html")});
    EXPECT_EQ(all.code, 2);
    EXPECT_TRUE(contains(all.err, "add {scene} or {index} to -o")) << all.err;
    const CliResult bad = run({"report", "--scene", "2", "--algorithms", "vcm", "--spp", "4", "--reference-algorithm", "nope", "-o",
                               path("out/bad.html")});
    EXPECT_EQ(bad.code, 2);
    EXPECT_TRUE(contains(bad.err, "unknown algorithm 'nope'")) << bad.err;
}

// Loads the report in headless Chromium: the script must run to its end (it marks <body>)
// without any console message (errors and uncaught exceptions are logged as CONSOLE lines).
TEST_F(ToolsReport, LoadsInChromiumWithoutConsoleErrors) {
    const char* chromium = "/usr/bin/chromium";
    if (!fs::exists(chromium)) GTEST_SKIP() << chromium << " is not installed (scripts/install-deps.sh installs it)";
    make_report();
    const std::string cmd = fmt::format(
        "timeout 120 {} --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --user-data-dir={} --enable-logging=stderr --v=0 "
        "--dump-dom 'file://{}#exposure=2&zoom=8&pixel=10,5' > {} 2> {}",
        chromium, path("profile"), path("out/report.html"), path("dom.html"), path("log.txt"));
    ASSERT_EQ(std::system(cmd.c_str()), 0) << read_text(path("log.txt"));
    const std::string dom = read_text(path("dom.html")), log = read_text(path("log.txt"));
    EXPECT_TRUE(contains(dom, "data-ready=\"yes\"")) << "the script did not finish";
    EXPECT_TRUE(contains(dom, "_ep2.png")) << "the exposure in the link was not applied";
    EXPECT_TRUE(contains(dom, "zoomed at pixel (10, 5)"));
    std::istringstream lines(log);
    for (std::string line; std::getline(lines, line);) EXPECT_FALSE(contains(line, ":CONSOLE")) << line;
}

// Ctrl-C during a report: the renders so far are kept and the page is still written (exit 130).
TEST_F(Tools, InterruptedReportStillWritesThePage) {
    // On a loaded machine the signal may come before the algorithms start (while the reference
    // renders, or before pathlab can handle it): such a run says nothing of the behaviour under
    // test, so it is repeated with a later signal.
    int status = 0;
    std::string html;
    for (const int delay : {2, 5, 12}) {
        const std::string cmd = fmt::format(
            "timeout --preserve-status -s INT {} {} report --scene 2 --algorithms direct-light,direct-mis --spp 100000000 "
            "--resolution 32x24 --reference-spp 64 -q -o {} 2> {}",
            delay, PATHLAB_BINARY, path("r.html"), path("err.txt"));
        status = std::system(cmd.c_str());
        html = fs::exists(path("r.html")) ? read_text(path("r.html")) : "";
        if (!html.empty() && !contains(html, "Interrupted while rendering the reference")) break;
    }
    ASSERT_TRUE(WIFEXITED(status)) << read_text(path("err.txt"));
    EXPECT_EQ(WEXITSTATUS(status), 130) << read_text(path("err.txt"));
    EXPECT_TRUE(contains(html, "Interrupted: direct-light stopped after")) << html.substr(0, 2000);
    EXPECT_TRUE(contains(html, "Interrupted: direct-mis was not rendered."));
    for (const std::string& s : image_sources(html)) {
        if (s.rfind("data:", 0) != 0) {
            EXPECT_TRUE(fs::exists(path(s))) << s;
        }
    }
}

TEST_F(Tools, ReportUsageErrors) {
    CliResult r = run({"report", "--scene", "2", "--algorithms", "1,3", "--spp", "4", "--time", "1", "-o", path("r.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "exactly one of --time")) << r.err;
    r = run({"report", "--scene", "2", "--algorithms", "1,pt-mis", "--spp", "4", "-o", path("r.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "converge to different images")) << r.err;
    write_image(Image(8, 8), path("ref.exr"));
    r = run({"report", "--scene", "2", "--algorithms", "1", "--spp", "4", "--reference", path("ref.exr"), "--resolution", "16x16",
             "-o", path("r.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "differs from the reference")) << r.err;
    r = run({"report", "--scene", "2", "--algorithms", "1", "--spp", "4", "--reference", path("nope.exr"), "-o", path("r.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, path("nope.exr"))) << r.err;
    r = run({"report", "--scene", "2", "--algorithms", "1", "--spp", "4", "--bogus", "-o", path("r.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "Valid options of report")) << r.err;
    EXPECT_FALSE(fs::exists(path("r.html")));
}

TEST(ToolsPlot, LogLogSvgHasDecadesSeriesAndEscapedText) {
    const std::string svg = log_log_svg({"t<itle", "x", "y", 400, 300, true},
                                        {{"a&b", "#123456", {{0.1, 1.0}, {1.0, 0.3}, {10.0, 0.1}}}, {"skip", "#000", {{0.0, 1.0}}}});
    EXPECT_TRUE(contains(svg, "t&lt;itle"));
    EXPECT_TRUE(contains(svg, "a&amp;b"));
    EXPECT_EQ(count(svg, "<polyline"), 1);  // the series without usable points draws nothing
    EXPECT_TRUE(contains(svg, ">0.1<"));
    EXPECT_TRUE(contains(svg, ">10<"));
    EXPECT_TRUE(contains(svg, "slope -1/2"));
}

}  // namespace
}  // namespace pathlab::test
