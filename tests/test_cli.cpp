// The command line: helpful errors with exit code 2, outputs and statistics, Ctrl-C.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "image/image_io.hpp"
#include "integrators/integrators.hpp"

namespace pathlab::test {
namespace {
namespace fs = std::filesystem;

class Cli : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-cli-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

TEST_F(Cli, UnknownSceneListsTheValidOnes) {
    const CliResult r = run({"--scene", "kitchen", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "unknown scene 'kitchen'")) << r.err;
    EXPECT_TRUE(contains(r.err, "ceiling-glossy")) << r.err;
    EXPECT_TRUE(contains(r.err, "env-diffuse")) << r.err;
}

TEST_F(Cli, UnknownAlgorithmListsTheValidOnes) {
    const CliResult r = run({"--scene", "0", "--algorithm", "bdpt-magic", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "unknown algorithm 'bdpt-magic'")) << r.err;
    EXPECT_TRUE(contains(r.err, "direct-light (1)")) << r.err;
    EXPECT_TRUE(contains(r.err, "eyelight")) << r.err;
}

TEST_F(Cli, BadResolutionIsExplained) {
    for (const char* bad : {"0x512", "512", "-3x4", "12x", "axb", "512x512x3"}) {
        const CliResult r = run({"--scene", "0", "--resolution", bad, "-o", path("x.exr")});
        EXPECT_EQ(r.code, 2) << bad;
        EXPECT_TRUE(contains(r.err, "invalid --resolution")) << r.err;
    }
}

TEST_F(Cli, NonPositiveSampleCountIsExplained) {
    for (const char* bad : {"0", "-4"}) {
        const CliResult r = run({"--scene", "0", "--spp", bad, "-o", path("x.exr")});
        EXPECT_EQ(r.code, 2) << bad;
        EXPECT_TRUE(contains(r.err, "--spp must be a positive")) << r.err;
    }
}

TEST_F(Cli, UnknownOptionListsTheValidOnes) {
    const CliResult r = run({"--sample-count", "4"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--sample-count")) << r.err;
    EXPECT_TRUE(contains(r.err, "Valid options")) << r.err;
    EXPECT_TRUE(contains(r.err, "--spp")) << r.err;
    EXPECT_TRUE(contains(r.err, "--scene")) << r.err;
}

TEST_F(Cli, UnwritableOutputFailsBeforeRendering) {
    const CliResult r = run({"--scene", "0", "-o", "/proc/pathlab/x.exr"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "/proc/pathlab/x.exr")) << r.err;
    EXPECT_FALSE(contains(r.err, "spp in")) << "rendered before failing: " << r.err;
}

TEST_F(Cli, UnknownOutputExtensionIsExplained) {
    const CliResult r = run({"--scene", "0", "-o", path("x.jpg")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, ".exr, .hdr, .pfm, .png")) << r.err;
}

TEST_F(Cli, SeveralScenesNeedAPlaceholderInTheOutputName) {
    const CliResult r = run({"--scene", "0,1", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "{scene}")) << r.err;
}

TEST_F(Cli, ScenesListsTheEightCourseScenes) {
    const CliResult r = run({"scenes"});
    EXPECT_EQ(r.code, 0);
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 8) << r.out;
    EXPECT_TRUE(contains(r.out, "5  box-glossy")) << r.out;
}

TEST_F(Cli, RendersScenesToEveryRequestedFormatWithStatistics) {
    const CliResult r = run({"--scene", "2,point-glossy", "--resolution", "24x16", "--spp", "3", "--quiet", "-o",
                             path("{index}-{scene}.exr"), "-o", path("{scene}.pfm"), "-o", path("{scene}.png"), "--stats",
                             path("{scene}.json")});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* f : {"2-ceiling-diffuse.exr", "ceiling-diffuse.pfm", "ceiling-diffuse.png", "1-point-glossy.exr"})
        EXPECT_TRUE(fs::exists(path(f))) << f;
    const Image exr = read_image(path("2-ceiling-diffuse.exr")), pfm = read_image(path("ceiling-diffuse.pfm"));
    EXPECT_EQ(exr.width(), 24);
    EXPECT_EQ(exr.height(), 16);
    for (size_t i = 0; i < exr.pixel_count(); ++i) ASSERT_EQ(exr[i], pfm[i]);
    const auto stats = nlohmann::json::parse(std::ifstream(path("ceiling-diffuse.json")));
    EXPECT_EQ(stats["scene"], "ceiling-diffuse");
    EXPECT_EQ(stats["algorithm"], "pt-mis");  // the default
    EXPECT_EQ(stats["spp"], 3);
    EXPECT_EQ(stats["resolution"], nlohmann::json::array({24, 16}));
    EXPECT_EQ(stats["samples"], 24 * 16 * 3);
    EXPECT_GE(stats["rays"].get<long>(), 24 * 16 * 3);
    EXPECT_EQ(stats["invalid_samples"], 0);
    EXPECT_GT(stats["samples_per_second"].get<double>(), 0);
}

TEST_F(Cli, AliasesSelectTheSameEstimator) {
    ASSERT_EQ(run({"-s", "0", "-a", "1", "--resolution", "8x8", "--spp", "2", "-q", "-o", path("a.pfm")}).code, 0);
    ASSERT_EQ(run({"-s", "point-diffuse", "-a", "direct-light", "--resolution", "8x8", "--spp", "2", "-q", "-o", path("b.pfm")}).code, 0);
    const Image a = read_image(path("a.pfm")), b = read_image(path("b.pfm"));
    for (size_t i = 0; i < a.pixel_count(); ++i) ASSERT_EQ(a[i], b[i]);
}

// Mitsuba's names select pathlab's integrators, on the command line and in scene files.
TEST_F(Cli, MitsubaNamesSelectTheLightTracerAndThePathTracer) {
    for (const auto& [mitsuba, name] : {std::pair{"ptracer", "lt"}, std::pair{"path", "pt-mis"}}) {
        ASSERT_EQ(run({"-s", "4", "-a", mitsuba, "--resolution", "8x8", "--spp", "2", "-q", "-o", path("m.pfm")}).code, 0);
        ASSERT_EQ(run({"-s", "4", "-a", name, "--resolution", "8x8", "--spp", "2", "-q", "-o", path("p.pfm")}).code, 0);
        const Image a = read_image(path("m.pfm")), b = read_image(path("p.pfm"));
        for (size_t i = 0; i < a.pixel_count(); ++i) ASSERT_EQ(a[i], b[i]) << mitsuba;
    }
    const std::string scene = path("lt.xml");
    std::ofstream(scene) << "<scene version=\"3.0.0\"><integrator type=\"ptracer\"><integer name=\"max_depth\" value=\"3\"/>"
                            "</integrator><shape type=\"rectangle\"/><emitter type=\"constant\"/></scene>";
    const CliResult r = run({"-s", scene, "--resolution", "8x8", "--spp", "2", "-q", "-o", path("lt.pfm"), "--stats", path("lt.json")});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream in(path("lt.json"));
    EXPECT_EQ(nlohmann::json::parse(in)["algorithm"], "lt");
}

// bdpt's options: the heuristic by name (others listed), --mis and --strategies only with bdpt,
// and --strategies writing its images and montages; bpt is bdpt, the power heuristic another image.
TEST_F(Cli, BdptOptionsAreCheckedAndTheStrategiesWritten) {
    CliResult r = run({"-s", "4", "-a", "bdpt", "--mis", "cubic", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "unknown MIS heuristic 'cubic'. Valid heuristics: balance, power")) << r.err;
    r = run({"-s", "4", "-a", "lt", "--mis", "power", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--mis chooses the heuristic of bdpt, vcm, bpm, upbp, mmlt, pt-mis, pt-mis3, direct-mis and volpath; lt has its own")) << r.err;
    r = run({"-s", "4", "-a", "lt", "--strategies", path("s"), "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--strategies writes the strategies of bdpt, not of lt")) << r.err;
    EXPECT_FALSE(fs::exists(path("x.exr")));

    fs::create_directories(path("s"));
    r = run({"-s", "4", "-a", "bpt", "--resolution", "8x8", "--spp", "4", "-q", "--strategies", path("s"), "--strategies-depth",
             "2", "-o", path("a.pfm")});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* f : {"montage-weighted.png", "montage-unweighted.png", "n0-s0-t2-weighted.exr", "n2-s3-t1-unweighted.exr",
                          "n2-s1-t3-weighted.stderr.exr"})
        EXPECT_TRUE(fs::exists(path("s") + "/" + f)) << f;
    EXPECT_FALSE(fs::exists(path("s") + "/n3-s0-t5-weighted.exr"));
    ASSERT_EQ(run({"-s", "4", "-a", "bdpt", "--mis", "power", "--resolution", "8x8", "--spp", "4", "-q", "-o", path("b.pfm")}).code, 0);
    const Image a = read_image(path("a.pfm")), b = read_image(path("b.pfm"));
    bool differ = false;
    for (size_t i = 0; i < a.pixel_count(); ++i) differ |= !(a[i] == b[i]);
    EXPECT_TRUE(differ) << "the power heuristic weighs the same paths differently";
}

// ic's options: only with ic, in range; --ic-records draws the records, the summary and --stats
// count them.
TEST_F(Cli, IcOptionsRecordsAndStatistics) {
    CliResult r = run({"-s", "2", "-a", "pt-mis", "--ic-error", "0.1", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "are ic's, not pt-mis's")) << r.err;
    r = run({"-s", "2", "-a", "bdpt", "--ic-records", path("records.png"), "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "are ic's, not bdpt's")) << r.err;
    EXPECT_FALSE(fs::exists(path("records.png")));
    r = run({"-s", "2", "-a", "ic", "--ic-rays", "2", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--ic-rays must be 4 to 65536")) << r.err;
    r = run({"-s", "2", "-a", "ic", "--resolution", "24x24", "--spp", "2", "--ic-rays", "32", "--ic-records", path("records.png"),
             "--stats", path("ic.json"), "-o", path("ic.exr")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "records ")) << r.err;
    EXPECT_TRUE(contains(r.err, "cache_seconds")) << r.err;
    EXPECT_GT(fs::file_size(path("records.png")), 100u);
    const auto stats = nlohmann::json::parse(std::ifstream(path("ic.json")));
    EXPECT_GT(stats["integrator"]["records"].get<double>(), 5.0);
    EXPECT_GE(stats["integrator"]["records_gathered"].get<double>(), stats["integrator"]["records"].get<double>());
}

// Sample indices that would wrap round (issue 45: --first-sample 2^64 - 1 rendered for a minute
// and wrote an image of 0 samples) are refused before anything renders; the last valid ones render.
TEST_F(Cli, SampleIndicesPastTheLastAreRefusedUpFront) {
    for (const char* first : {"18446744073709551615", "4611686018427387904"}) {
        const CliResult r = run({"-s", "2", "--first-sample", first, "--resolution", "8x8", "-o", path("far.exr")});
        EXPECT_EQ(r.code, 2) << first;
        EXPECT_TRUE(contains(r.err, "reaches past the last sample index, 2^62 = 4611686018427387904")) << r.err;
    }
    CliResult r = run({"-s", "2", "--first-sample", "4611686018427387902", "--spp", "3", "--resolution", "8x8", "-o", path("far.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_FALSE(fs::exists(path("far.exr")));
    r = run({"-s", "2", "--first-sample", "4611686018427387902", "--spp", "2", "--resolution", "8x8", "-q", "-o", path("far.exr")});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("far.exr")));
    // --time without --spp has no last sample: it rendered passes past 2^62.
    r = run({"-s", "2", "--first-sample", "4611686018427387900", "--time", "1", "--resolution", "8x8", "-q", "-o", path("timed.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "with --time and no --spp may reach past the last sample index")) << r.err;
    EXPECT_FALSE(fs::exists(path("timed.exr")));
}

// sppm's options: only with sppm, in range; a render with them runs.
TEST_F(Cli, SppmOptionsAreChecked) {
    CliResult r = run({"-s", "2", "-a", "pt-mis", "--photons", "1000", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--photons sets the light paths of sppm, ppm and pm; pt-mis has no such count")) << r.err;
    r = run({"-s", "2", "-a", "pm", "--alpha", "0.5", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--alpha is the radius reduction of sppm, ppm, vcm, bpm and upbp, not pm's")) << r.err;
    r = run({"-s", "2", "-a", "sppm", "--alpha", "1.5", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--alpha must be in (0, 1]")) << r.err;
    r = run({"-s", "2", "-a", "sppm", "--radius", "-1", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--radius must be zero")) << r.err;
    r = run({"-s", "2", "-a", "sppm", "--photons", "2000", "--radius", "0.05", "--alpha", "0.5", "--resolution", "8x8", "--spp", "3",
             "-q", "-o", path("s.pfm")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(read_image(path("s.pfm")).pixel_count(), 64u);
}

// Ctrl-C during a long render: the binary writes the passes it finished, normalised by them,
// so the image equals a one-shot render with that many samples, bit for bit.
TEST_F(Cli, InterruptedRenderWritesWhatItHasCorrectlyNormalised) {
    const std::string common = fmt::format("{} --scene 3 --resolution 64x64 --seed 9 --quiet", PATHLAB_BINARY);
    // On a loaded machine the signal may come before pathlab has installed its handler (it
    // then dies of it and writes nothing): such a run says nothing of the behaviour under
    // test, so it is repeated with a later signal.
    int status = 0;
    for (const double delay : {1.5, 4.0, 10.0}) {
        const std::string cmd = fmt::format("timeout --preserve-status -s INT {} {} --spp 100000000 -o {} --stats {}", delay,
                                            common, path("interrupted.exr"), path("interrupted.json"));
        status = std::system(cmd.c_str());
        if (fs::exists(path("interrupted.json"))) break;
    }
    ASSERT_TRUE(fs::exists(path("interrupted.json"))) << "pathlab never got as far as rendering before the signal";
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    const auto stats = nlohmann::json::parse(std::ifstream(path("interrupted.json")));
    EXPECT_TRUE(stats["interrupted"].get<bool>());
    const int spp = stats["spp"];
    ASSERT_GT(spp, 0);
    ASSERT_EQ(std::system(fmt::format("{} --spp {} -o {}", common, spp, path("oneshot.exr")).c_str()), 0);
    const Image a = read_image(path("interrupted.exr")), b = read_image(path("oneshot.exr"));
    for (size_t i = 0; i < a.pixel_count(); ++i) ASSERT_EQ(a[i], b[i]) << i;
}

}  // namespace
}  // namespace pathlab::test

namespace pathlab::test {
namespace {

// A small scene file whose settings the command line may override.
std::string write_scene(const std::string& file, const std::string& integrator = "direct") {
    std::ofstream(file) << "<scene version=\"3.0.0\">\n"
                           "  <default name=\"r\" value=\"0.5\"/>\n"
                           "  <integrator type=\"" << integrator << "\"/>\n"
                           "  <sensor type=\"perspective\"><transform name=\"to_world\"><lookat origin=\"0,-3,0\" target=\"0,0,0\" up=\"0,0,1\"/></transform>\n"
                           "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"20\"/><integer name=\"height\" value=\"10\"/><rfilter type=\"box\"/></film>\n"
                           "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"3\"/></sampler></sensor>\n"
                           "  <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>\n"
                           "  <emitter type=\"constant\"/>\n"
                           "</scene>\n";
    return file;
}

// Scene files of one name in folders of their own (Bitterli's layout: DIR/scene.xml): {dir} is
// the folder, and the default names take it when they would collide (they were refused), or
// {path} where the folders' names collide too.
TEST_F(Cli, ScenesOfOneNameInTheirOwnFoldersGetTheFolderInTheirNames) {
    fs::create_directories(path("kitchen")), fs::create_directories(path("bathroom"));
    const std::string a = write_scene(path("kitchen/scene.xml")), b = write_scene(path("bathroom/scene.xml"));
    CliResult r = run({"-s", a + "," + b, "--spp", "1", "--resolution", "8x4", "-q", "-o", path("{dir}-{scene}.pfm")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("kitchen-scene.pfm")));
    EXPECT_TRUE(fs::exists(path("bathroom-scene.pfm")));
    // The default pattern, run from the test's folder.
    const fs::path before = fs::current_path();
    fs::current_path(path(""));
    r = run({"-s", a + "," + b, "--spp", "1", "--resolution", "8x4", "-q"});
    fs::current_path(before);
    ASSERT_EQ(r.code, 0) << r.err;
    int kitchen = 0, bathroom = 0;
    for (const auto& e : fs::directory_iterator(path("out"))) {
        kitchen += contains(e.path().filename().string(), "kitchen-scene-direct-mis.");
        bathroom += contains(e.path().filename().string(), "bathroom-scene-direct-mis.");
    }
    EXPECT_EQ(kitchen, 2);  // .exr and .png
    EXPECT_EQ(bathroom, 2);
    // Folders of one name too (a/k/scene.xml, b/k/scene.xml): the default names take the path
    // ({dir} could not tell them apart, and the render was refused).
    fs::create_directories(path("a/k")), fs::create_directories(path("b/k"));
    const std::string ak = write_scene(path("a/k/scene.xml")), bk = write_scene(path("b/k/scene.xml"));
    fs::current_path(path(""));
    r = run({"-s", ak + "," + bk, "--spp", "1", "--resolution", "8x4", "-q"});
    fs::current_path(before);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("out/scene-a-k-scene-direct-mis.exr")));
    EXPECT_TRUE(fs::exists(path("out/scene-b-k-scene-direct-mis.png")));
    // One scene alone keeps the names it always had.
    r = run({"-s", a, "--spp", "1", "--resolution", "8x4", "-q", "-o", path("{scene}.pfm")});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("scene.pfm")));
}

// -a all renders every estimator, one image each (every one that renders the scene; at a finite
// depth, which mmlt needs).
TEST_F(Cli, AlgorithmAllRendersEveryEstimator) {
    const CliResult r =
        run({"-s", "2", "-a", "all", "--spp", "1", "--max-depth", "6", "--resolution", "4x4", "-q", "-o", path("all/{algorithm}.pfm")});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const IntegratorInfo& info : integrators()) EXPECT_TRUE(fs::exists(path("all/" + info.name + ".pfm"))) << info.name;
    // On a scene with a medium, every estimator that renders media; the others are left out with
    // a note naming them and why (the first refusal stopped the whole command).
    const CliResult fog = run({"--scene", std::string(PATHLAB_SOURCE_DIR) + "/scenes/fog-box.xml", "-a", "all", "--spp", "1", "--max-depth", "6",
                               "--resolution", "4x4", "-o", path("fog/{algorithm}.pfm")});
    ASSERT_EQ(fog.code, 0) << fog.err;
    EXPECT_TRUE(contains(fog.err, "note: -a all on fog-box: eyelight, ")) << fog.err;
    EXPECT_TRUE(contains(fog.err, "left out, as they cannot render it (e.g. eyelight does not render participating media")) << fog.err;
    for (const IntegratorInfo& info : integrators()) EXPECT_EQ(fs::exists(path("fog/" + info.name + ".pfm")), info.media) << info.name;
}

TEST_F(Cli, SceneFileSettingsApplyUnlessTheCommandLineGivesThem) {
    const std::string scene = write_scene(path("ball.xml"));
    CliResult r = run({"--scene", scene, "-q", "-o", path("{scene}-{algorithm}.pfm"), "--stats", path("a.json")});
    ASSERT_EQ(r.code, 0) << r.err;
    nlohmann::json j = nlohmann::json::parse(std::ifstream(path("a.json")));
    EXPECT_EQ(j["algorithm"], "direct-mis");  // <integrator type="direct">
    EXPECT_EQ(j["spp"], 3);
    EXPECT_EQ(j["resolution"], nlohmann::json::array({20, 10}));
    EXPECT_TRUE(fs::exists(path("ball-direct-mis.pfm")));

    r = run({"--scene", scene, "-q", "-a", "pt-mis", "--spp", "2", "--resolution", "8x4", "-D", "r=0.25", "-o",
             path("b.pfm"), "--stats", path("b.json")});
    ASSERT_EQ(r.code, 0) << r.err;
    j = nlohmann::json::parse(std::ifstream(path("b.json")));
    EXPECT_EQ(j["algorithm"], "pt-mis");
    EXPECT_EQ(j["spp"], 2);
    EXPECT_EQ(j["resolution"], nlohmann::json::array({8, 4}));
}

TEST_F(Cli, SceneFileErrorsGiveFileLineColumnAndExitCode2) {
    std::ofstream(path("bad.xml")) << "<scene version=\"3.0.0\">\n  <shape type=\"torus\"/>\n</scene>\n";
    CliResult r = run({"--scene", path("bad.xml"), "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, path("bad.xml") + ":2:3: error: unsupported shape type 'torus'")) << r.err;
    r = run({"--scene", path("missing.xml"), "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "missing.xml: error: cannot open the scene file")) << r.err;
    r = run({"--scene", write_scene(path("ok.xml")), "-D", "novalue", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "expected name=value")) << r.err;
    // An integrator pathlab does not have: an error that says where and that -a replaces it; with
    // -a the scene renders, with a note.
    r = run({"--scene", write_scene(path("odd.xml"), "stokes"), "-o", path("x.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, path("odd.xml") + ":")) << r.err;
    EXPECT_TRUE(contains(r.err, "unsupported integrator type 'stokes'")) << r.err;
    EXPECT_TRUE(contains(r.err, "or choose one of pathlab's with -a NAME")) << r.err;
    EXPECT_FALSE(fs::exists(path("x.exr")));
    r = run({"--scene", path("odd.xml"), "-a", "pt-mis", "--spp", "1", "--resolution", "4x4", "-o", path("x.exr")});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "note: the scene's integrator is not one of pathlab's; -a pt-mis renders the scene instead")) << r.err;
    EXPECT_TRUE(fs::exists(path("x.exr")));
}

}  // namespace
}  // namespace pathlab::test
