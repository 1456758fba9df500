// The lab around the renderer (issue 23): the command-line conventions (positional scenes, the
// render subcommand, usage without arguments, unused -D values, -a lists in every command),
// every command on scene files, reference manifests that refuse a reference of another scene,
// size or estimator family, convert and info, created output directories. (A second Ctrl-C:
// Hostile.ASecondSignalAbortsAtOnce.)
#include <gtest/gtest.h>

#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfStringAttribute.h>
#include <ImfDoubleAttribute.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "image/image_io.hpp"

namespace pathlab::test {
namespace {
namespace fs = std::filesystem;

class Lab : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-lab-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    // A small scene file with one parameter, $r (the ball's radius).
    std::string ball(const std::string& name = "ball.xml") const {
        std::ofstream(path(name)) << "<scene version=\"3.0.0\">\n"
                                     "  <default name=\"r\" value=\"0.5\"/>\n"
                                     "  <sensor type=\"perspective\"><transform name=\"to_world\"><lookat origin=\"0,-3,0\" target=\"0,0,0\" up=\"0,0,1\"/></transform>\n"
                                     "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"12\"/><integer name=\"height\" value=\"8\"/><rfilter type=\"box\"/></film></sensor>\n"
                                     "  <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>\n"
                                     "  <emitter type=\"constant\"/>\n"
                                     "</scene>\n";
        return path(name);
    }
    fs::path dir_;
};

std::string read_text(const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

bool same_pixels(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height()) return false;
    for (size_t i = 0; i < a.pixel_count(); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(Rgb)) != 0) return false;
    return true;
}

// ---- conventions ----------------------------------------------------------------------------

TEST_F(Lab, NoArgumentsPrintsTheUsageAndExitsWith2) {
    const CliResult r = run({});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "Usage: pathlab SCENE [options]")) << r.err;
    EXPECT_TRUE(contains(r.err, "report")) << r.err;  // the commands are listed
    const CliResult none = run({"--spp", "4"});
    EXPECT_EQ(none.code, 2);
    EXPECT_TRUE(contains(none.err, "no scene given")) << none.err;
}

TEST_F(Lab, HelpSaysWhatTheFirstAndTheSecondCtrlCDo) {
    for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{{"--help"}, {"report", "--help"}, {"render", "--help"}}) {
        const CliResult r = run(args);
        EXPECT_EQ(r.code, 0);
        EXPECT_TRUE(contains(r.out, "the first stops after the current pass and writes what was rendered")) << r.out;
        EXPECT_TRUE(contains(r.out, "a second one aborts at once, prints that it aborted and writes no image")) << r.out;
        EXPECT_TRUE(contains(r.out, "exit code 130")) << r.out;
    }
}

TEST_F(Lab, PositionalSceneRenderSubcommandAndOptionAreTheSame) {
    const std::vector<std::string> common = {"--resolution", "10x8", "--spp", "2", "--seed", "5", "-q", "-o"};
    const auto render = [&](std::vector<std::string> head, const std::string& out) {
        head.insert(head.end(), common.begin(), common.end());
        head.push_back(path(out));
        const CliResult r = run(head);
        EXPECT_EQ(r.code, 0) << r.err;
        return read_image(path(out));
    };
    const Image a = render({"3"}, "a.pfm"), b = render({"render", "3"}, "b.pfm"), c = render({"--scene", "ceiling-glossy"}, "c.pfm");
    EXPECT_TRUE(same_pixels(a, b));
    EXPECT_TRUE(same_pixels(a, c));
    const Image f = render({ball()}, "f.pfm"), g = render({"-s", ball()}, "g.pfm");
    EXPECT_TRUE(same_pixels(f, g));
    // Several positional scenes are a list.
    CliResult r = run({"2", ball(), "--resolution", "6x4", "--spp", "1", "-q", "-o", path("{scene}.pfm")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("ceiling-diffuse.pfm")));
    EXPECT_TRUE(fs::exists(path("ball.pfm")));
    r = run({"2", "--scene", "3", "-o", path("x.pfm")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "the scene is given twice")) << r.err;
}

TEST_F(Lab, ADefineNoSceneUsesIsAnErrorListingTheParameters) {
    CliResult r = run({ball(), "-D", "rr=0.3", "-o", path("x.pfm")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "-D rr=0.3: no scene uses $rr")) << r.err;
    EXPECT_TRUE(contains(r.err, "r (now 0.5)")) << r.err;
    EXPECT_FALSE(fs::exists(path("x.pfm")));
    r = run({"3", "-D", "spp=8", "-o", path("x.pfm")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "the built-in scenes take no parameters")) << r.err;
    // Used by one scene of a list: fine.
    r = run({"2", ball(), "-D", "r=0.3", "--spp", "1", "--resolution", "4x4", "-q", "-o", path("{scene}.pfm")});
    EXPECT_EQ(r.code, 0) << r.err;
    // The same rule in the other commands.
    r = run({"reference", ball(), "-D", "radius=1", "--out", path("refs")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "no scene uses $radius")) << r.err;
}

TEST_F(Lab, OutputDirectoriesThatDoNotExistAreCreated) {
    const CliResult r = run({"2", "--resolution", "4x4", "--spp", "1", "-q", "-o", path("new/deeper/x.png"), "--stats", path("stats/dir/s.json")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("new/deeper/x.png")));
    EXPECT_TRUE(fs::exists(path("stats/dir/s.json")));
}

// ---- -a lists and scene files in every command --------------------------------------------

TEST_F(Lab, AlgorithmListsAndSceneFilesInEveryCommand) {
    // render: one image per algorithm.
    CliResult r = run({"2", "-a", "1,direct-mis", "--resolution", "8x6", "--spp", "2", "-q", "-o", path("{algorithm}.pfm")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("direct-light.pfm")));
    EXPECT_TRUE(fs::exists(path("direct-mis.pfm")));
    r = run({"2", "-a", "1,3", "--spp", "1", "-o", path("same.pfm")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "{algorithm}")) << r.err;
    r = run({"2", "-a", "1,1", "-o", path("{algorithm}.pfm")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "listed twice")) << r.err;

    // reference: a built-in scene and a scene file, two algorithms into {algorithm} directories.
    r = run({"reference", "2", ball(), "-a", "direct-mis,pt-mis", "--out", path("refs/{algorithm}"), "--resolution", "16x12", "--spp", "64", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* f : {"refs/direct-mis/2-ceiling-diffuse.exr", "refs/direct-mis/ball.exr", "refs/pt-mis/ball.stderr.exr", "refs/pt-mis/manifest.json"})
        EXPECT_TRUE(fs::exists(path(f))) << f;
    const auto manifest = nlohmann::json::parse(std::ifstream(path("refs/direct-mis/manifest.json")));
    ASSERT_EQ(manifest["scenes"].size(), 2u);
    const nlohmann::json& builtin = manifest["scenes"][0];
    const nlohmann::json& file = manifest["scenes"][1];
    EXPECT_EQ(builtin["index"], 2);
    EXPECT_EQ(builtin["family"], "direct illumination");
    EXPECT_EQ(file["scene_file"], ball());
    EXPECT_EQ(file["scene_hash"].get<std::string>().size(), 16u);
    EXPECT_EQ(file["parameters"]["r"], "0.5");
    EXPECT_EQ(file["resolution"], nlohmann::json::array({16, 12}));
    r = run({"reference", "2", "-a", "direct-mis,pt-mis", "--out", path("refs/one")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "{algorithm}")) << r.err;

    // check: both direct estimators, on both scenes (the scene file found by its stem).
    r = run({"check", "2", ball(), "-a", "1,direct-mis", "--references", path("refs/direct-mis"), "--spp", "8"});
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 2 * 3 + 1) << r.out;  // a header and 2 verdicts per algorithm, a summary
    EXPECT_TRUE(std::regex_search(r.out, std::regex("- ball +OK +ball.exr"))) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("check direct-light at 8 spp"))) << r.out;

    // report: -a, and --algorithms as its alias; a scene file; a directory of references.
    for (const char* option : {"-a", "--algorithms"}) {
        r = run({"report", ball(), option, "pt-mis,bdpt", "--spp", "2", "--reference", path("refs/pt-mis"), "-q", "-o", path("r.html")});
        ASSERT_EQ(r.code, 0) << r.err;
        const std::string html = read_text(path("r.html"));
        EXPECT_TRUE(contains(html, "<td>bdpt</td>"));
        EXPECT_TRUE(contains(html, "ball.exr (given)"));
    }
}

// ---- references that do not fit are refused ------------------------------------------------

TEST_F(Lab, AReferenceOfAnotherSceneSizeOrFamilyIsRefused) {
    CliResult r = run({"reference", "2", ball(), "-a", "direct-mis", "--out", path("refs"), "--resolution", "12x8", "--spp", "16", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    // Another family: pt-mis converges to global illumination, the references are direct.
    r = run({"check", "2", "-a", "pt-mis", "--references", path("refs"), "--spp", "2"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "was rendered with direct-mis (direct illumination)")) << r.err;
    EXPECT_TRUE(contains(r.err, "converges to global illumination")) << r.err;
    EXPECT_FALSE(contains(r.out, " OK ")) << "rendered before refusing";
    // Another size.
    r = run({"check", "2", "-a", "1", "--references", path("refs"), "--spp", "2", "--resolution", "6x4"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "is 12x8, but --resolution asks for 6x4")) << r.err;
    // Another scene: scene 2's reference given to a report of scene 3.
    r = run({"report", "3", "-a", "3", "--spp", "2", "--reference", path("refs/2-ceiling-diffuse.exr"), "-q", "-o", path("r.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "is a reference of scene 2 ceiling-diffuse, not of scene 3 ceiling-glossy")) << r.err;
    EXPECT_FALSE(fs::exists(path("r.html")));
    // A manifest whose entry gives one scene's index and another's name (it went by the index).
    {
        auto manifest = nlohmann::json::parse(std::ifstream(path("refs/manifest.json")));
        for (auto& e : manifest["scenes"])
            if (e.value("file", "") == "2-ceiling-diffuse.exr") e["scene"] = "ceiling-glossy";
        std::ofstream(path("refs/manifest.json")) << manifest.dump(2);
        r = run({"check", "2", "-a", "direct-mis", "--references", path("refs"), "--spp", "2"});
        EXPECT_EQ(r.code, 2);
        EXPECT_TRUE(contains(r.err, "is a reference of scene 2 by its manifest entry's index, but of ceiling-glossy by its name")) << r.err;
        for (auto& e : manifest["scenes"])
            if (e.value("file", "") == "2-ceiling-diffuse.exr") e["scene"] = "ceiling-diffuse";
        std::ofstream(path("refs/manifest.json")) << manifest.dump(2);
    }
    // The scene file with another parameter value, then the file changed.
    r = run({"check", ball(), "-D", "r=0.25", "-a", "3", "--references", path("refs"), "--spp", "2"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "with the parameters r=0.5, not r=0.25")) << r.err;
    const std::string scene_file = ball();
    std::ofstream(scene_file, std::ios::app) << "<!-- edited -->\n";
    r = run({"report", scene_file, "-a", "3", "--spp", "2", "--reference", path("refs/ball.exr"), "-q", "-o", path("r.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "it or a file it reads has changed since")) << r.err;
    // The fitting ones are accepted.
    r = run({"check", "2", "-a", "1", "--references", path("refs"), "--spp", "4"});
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    r = run({"report", "2", "-a", "3", "--spp", "2", "--reference", path("refs/2-ceiling-diffuse.exr"), "-q", "-o", path("ok.html")});
    EXPECT_EQ(r.code, 0) << r.err;
    // The report's own reference is recorded too, so reusing it is checked the same way.
    r = run({"report", "2", "-a", "3", "--spp", "2", "--resolution", "8x6", "--reference-spp", "4", "-q", "-o", path("own.html")});
    ASSERT_EQ(r.code, 0) << r.err;
    r = run({"report", "3", "-a", "3", "--spp", "2", "--reference", path("own_files/reference.exr"), "-q", "-o", path("again.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "not of scene 3")) << r.err;
}

// One scene hash for everything: the manifest's equals the render's EXR header (pathlab:sceneHash),
// and it changes with a file the scene only includes or a mesh it reads.
TEST_F(Lab, TheSceneHashCoversIncludedFilesAndMeshesAndIsTheRendersOwn) {
    fs::create_directories(path("parts"));
    std::ofstream(path("parts/light.xml")) << "<scene version=\"3.0.0\"><emitter type=\"constant\"/></scene>\n";
    std::ofstream(path("parts/tri.obj")) << "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n";
    std::ofstream(path("inc.xml")) << "<scene version=\"3.0.0\">\n"
                                      "  <sensor type=\"perspective\"><transform name=\"to_world\"><lookat origin=\"0,-3,0\" target=\"0,0,0\" up=\"0,0,1\"/></transform>\n"
                                      "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"6\"/><rfilter type=\"box\"/></film></sensor>\n"
                                      "  <include filename=\"parts/light.xml\"/>\n"
                                      "  <shape type=\"obj\"><string name=\"filename\" value=\"parts/tri.obj\"/></shape>\n"
                                      "</scene>\n";
    CliResult r = run({"reference", path("inc.xml"), "-a", "direct-mis", "--out", path("refs"), "--spp", "4", "-q"});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto manifest = nlohmann::json::parse(std::ifstream(path("refs/manifest.json")));
    const std::string hash = manifest["scenes"][0]["scene_hash"].get<std::string>();
    ASSERT_EQ(hash.size(), 16u);
    r = run({path("inc.xml"), "-a", "direct-mis", "--spp", "2", "-q", "-o", path("inc.exr")});
    ASSERT_EQ(r.code, 0) << r.err;
    ExrExtras extras;
    read_exr(path("inc.exr"), extras);
    std::string header_hash;
    for (const auto& [k, v] : extras.attributes)
        if (k == "pathlab:sceneHash") header_hash = v;
    EXPECT_EQ(header_hash, hash);
    // The reference fits as long as nothing the scene reads changes...
    r = run({"check", path("inc.xml"), "-a", "3", "--references", path("refs"), "--spp", "2"});
    EXPECT_NE(r.code, 2) << r.err;
    // ... then an edit of the included file, and of the mesh, makes it another scene.
    std::ofstream(path("parts/light.xml")) << "<scene version=\"3.0.0\"><emitter type=\"constant\"><rgb name=\"radiance\" value=\"2\"/></emitter></scene>\n";
    r = run({"check", path("inc.xml"), "-a", "3", "--references", path("refs"), "--spp", "2"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "it or a file it reads has changed since")) << r.err;
    std::ofstream(path("parts/light.xml")) << "<scene version=\"3.0.0\"><emitter type=\"constant\"/></scene>\n";
    r = run({"check", path("inc.xml"), "-a", "3", "--references", path("refs"), "--spp", "2"});
    EXPECT_NE(r.code, 2) << r.err;
    std::ofstream(path("parts/tri.obj"), std::ios::app) << "# edited\n";
    r = run({"check", path("inc.xml"), "-a", "3", "--references", path("refs"), "--spp", "2"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "it or a file it reads has changed since")) << r.err;
}

TEST_F(Lab, ReportSaysHowLongItsReferenceTakesBeforeItsAlgorithms) {
    const CliResult r = run({"report", "2", "-a", "1,3", "--time", "0.05", "--resolution", "16x12", "--reference-spp", "64", "-o", path("t.html")});
    ASSERT_EQ(r.code, 0) << r.err;
    const size_t said = r.err.find("reference: none given, so it is rendered first with pt-mis --max-depth 1 at 64 spp");
    const size_t estimate = r.err.find("reference: about ");
    const size_t first = r.err.find("direct-light\n");
    ASSERT_NE(said, std::string::npos) << r.err;
    ASSERT_NE(estimate, std::string::npos) << r.err;
    EXPECT_TRUE(contains(r.err, "to use one: --reference FILE")) << r.err;
    EXPECT_TRUE(contains(r.err, "then 2 x 0.05 s for the algorithms")) << r.err;
    EXPECT_LT(said, estimate);
    EXPECT_LT(estimate, first);
}

// ---- the report page --------------------------------------------------------------------------

TEST_F(Lab, ReportHasStandardErrorsEfficiencyBothCurvesCsvAndInsets) {
    const CliResult r = run({"report", "2", "-a", "1,3", "--spp", "6", "--resolution", "32x24", "--reference-spp", "32", "--crop", "4,6,8,5",
                             "--crop", "20,10,12,14", "-q", "-o", path("p.html")});
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string html = read_text(path("p.html"));
    EXPECT_TRUE(contains(html, "Per-pixel standard error"));
    EXPECT_TRUE(fs::exists(path("p_files/direct-mis_stderr.png")));
    EXPECT_TRUE(contains(html, "efficiency 1/(MSE·s)"));
    EXPECT_TRUE(contains(html, "over samples per pixel"));
    EXPECT_TRUE(contains(html, "class=\"crop\""));
    EXPECT_TRUE(fs::exists(path("p_files/direct-light_crop1_e0.png")));
    EXPECT_EQ(read_png8(path("p_files/direct-light_crop1_e0.png")).width, 12);
    // The table as CSV: the page's numbers; efficiency = 1 / (RMSE^2 x seconds).
    const std::string csv = read_text(path("p_files/table.csv"));
    std::istringstream lines(csv);
    std::string header, row;
    std::getline(lines, header);
    EXPECT_EQ(header.rfind("algorithm,spp,seconds,msamples_per_second,rmse,relmse,efficiency", 0), 0u) << header;
    int rows = 0;
    while (std::getline(lines, row)) {
        std::vector<std::string> f;
        for (size_t start = 0, comma; start <= row.size(); start = comma + 1) {
            comma = std::min(row.find(',', start), row.size());
            f.push_back(row.substr(start, comma - start));
        }
        ASSERT_GE(f.size(), 7u) << row;
        EXPECT_EQ(f[1], "6");
        const double seconds = std::stod(f[2]), rmse = std::stod(f[4]), efficiency = std::stod(f[6]);
        EXPECT_NEAR(efficiency * rmse * rmse * seconds, 1.0, 1e-4) << row;
        ++rows;
    }
    EXPECT_EQ(rows, 2);
    const std::string curves = read_text(path("p_files/convergence.csv"));
    EXPECT_EQ(curves.rfind("algorithm,seconds,spp,rmse\n", 0), 0u);
    EXPECT_TRUE(std::regex_search(curves, std::regex("\ndirect-mis,[0-9.e-]+,6,"))) << curves;
    // A crop outside the image is refused before anything renders.
    const CliResult bad = run({"report", "2", "-a", "3", "--spp", "2", "--resolution", "8x8", "--reference-spp", "2", "--crop", "4,4,8,8", "-q",
                               "-o", path("bad.html")});
    EXPECT_EQ(bad.code, 2);
    EXPECT_TRUE(contains(bad.err, "not inside the 8x8 image")) << bad.err;
}

// --guide-pixel: ppg's learned distribution at a pixel's first hit, as a picture in the report.
TEST_F(Lab, ReportShowsWhatTheGuideLearnedAtAPixel) {
    const CliResult r = run({"report", "3", "-a", "ppg,pt-mis", "--spp", "2", "--resolution", "24x16", "--reference-spp", "4",
                             "--guide-pixel", "12,10", "-q", "-o", path("g.html")});
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string html = read_text(path("g.html"));
    EXPECT_TRUE(contains(html, "What the guide learned"));
    EXPECT_TRUE(contains(html, "pixel (12, 10): first hit at"));
    EXPECT_TRUE(contains(html, "BSDF sampling fraction there 0.5 (--guiding-fraction)"));
    // A scene file asking ppg for the learned fraction and the mixtures: the leaf's own fraction, and the model named.
    std::string lampshade = read_text(std::string(PATHLAB_SOURCE_DIR) + "/scenes/lampshade.xml");
    const std::string bdpt = "<integrator type=\"bdpt\"/>";
    ASSERT_NE(lampshade.find(bdpt), std::string::npos);
    lampshade.replace(lampshade.find(bdpt), bdpt.size(), "<integrator type=\"ppg\"><string name=\"guiding_fraction\" value=\"learned\"/>"
                      "<string name=\"guiding\" value=\"vmm\"/></integrator>");
    {
        std::ofstream(path("learned.xml")) << lampshade;
    }
    const CliResult learned = run({"report", path("learned.xml"), "-a", "ppg", "--spp", "2", "--resolution", "24x16", "--reference-spp", "2",
                                   "--guide-pixel", "12,12", "-q", "-o", path("l.html")});
    ASSERT_EQ(learned.code, 0) << learned.err;
    EXPECT_TRUE(contains(read_text(path("l.html")), "(learned)")) << "the learned fraction of the leaf at pixel (12, 12)";
    EXPECT_TRUE(contains(read_text(path("l.html")), "von Mises-Fisher mixture (--guiding vmm)"));
    EXPECT_TRUE(fs::exists(path("g_files/ppg_guide.png")));
    EXPECT_FALSE(fs::exists(path("g_files/pt-mis_guide.png")));
    EXPECT_EQ(read_png8(path("g_files/ppg_guide.png")).width, 256);
    // Refused before anything renders: without ppg, and outside the image.
    const CliResult without = run({"report", "3", "-a", "pt-mis", "--spp", "2", "--resolution", "8x8", "--guide-pixel", "1,1", "-q", "-o", path("b.html")});
    EXPECT_EQ(without.code, 2);
    EXPECT_TRUE(contains(without.err, "add ppg to -a")) << without.err;
    const CliResult outside = run({"report", "3", "-a", "ppg", "--spp", "2", "--resolution", "8x8", "--reference-spp", "2", "--guide-pixel", "8,1",
                                   "-q", "-o", path("c.html")});
    EXPECT_EQ(outside.code, 2);
    EXPECT_TRUE(contains(outside.err, "not inside the 8x8 image")) << outside.err;
}

TEST_F(Lab, ReportOfSeveralScenesWritesAPageEach) {
    CliResult r = run({"report", "2", ball(), "-a", "3", "--spp", "2", "--resolution", "8x6", "--reference-spp", "4", "-q", "-o", path("one.html")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "add {scene} or {index} to -o")) << r.err;
    r = run({"report", "2", ball(), "-a", "3", "--spp", "2", "--resolution", "8x6", "--reference-spp", "4", "-q", "-o", path("{scene}.html")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(read_text(path("ball.html")), "ball (" + ball() + ")"));
    EXPECT_TRUE(contains(read_text(path("ceiling-diffuse.html")), "scene 2 ceiling-diffuse"));
}

// ---- convert and info -----------------------------------------------------------------------

Image test_image(int w, int h) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) img.at(x, y) = Rgb(0.01f * float(x), 0.3f + 0.05f * float(y), float(x * y) / 7.0f);
    return img;
}

TEST_F(Lab, ConvertRoundTripsCropsAndScales) {
    write_image(test_image(9, 7), path("a.exr"));
    ASSERT_EQ(run({"convert", path("a.exr"), path("b.pfm")}).code, 0);
    ASSERT_EQ(run({"convert", path("b.pfm"), path("c.exr")}).code, 0);
    EXPECT_TRUE(same_pixels(read_image(path("a.exr")), read_image(path("c.exr"))));
    // Crop: the pixels of the rectangle; exposure 1: exactly twice the values.
    ASSERT_EQ(run({"convert", path("a.exr"), path("crop.exr"), "--crop", "2,3,4,2", "--exposure", "1"}).code, 0);
    const Image a = read_image(path("a.exr")), cropped = read_image(path("crop.exr"));
    ASSERT_EQ(cropped.width(), 4);
    ASSERT_EQ(cropped.height(), 2);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) EXPECT_EQ(cropped.at(x, y), a.at(2 + x, 3 + y) * 2.0f);
    // PNG: decoded to linear and encoded again, every 8-bit code survives.
    Image8 codes{256, 1, std::vector<uint8_t>(256 * 3)};
    for (int i = 0; i < 256 * 3; ++i) codes.rgb[size_t(i)] = uint8_t((i * 7) % 256);
    write_png8(codes, path("codes.png"));
    ASSERT_EQ(run({"convert", path("codes.png"), path("codes.exr")}).code, 0);
    ASSERT_EQ(run({"convert", path("codes.exr"), path("again.png")}).code, 0);
    EXPECT_EQ(read_png8(path("again.png")).rgb, codes.rgb);
    // HDR (RGBE) keeps about 1%.
    ASSERT_EQ(run({"convert", path("a.exr"), path("a.hdr")}).code, 0);
    const Image hdr = read_image(path("a.hdr"));
    for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(hdr[i][c], a[i][c], 0.01 * std::max(a[i].x, std::max(a[i].y, a[i].z)) + 1e-6);
    // Bad usage.
    CliResult r = run({"convert", path("a.exr"), path("x.exr"), "--crop", "5,5,5,5"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "not inside the 9x7 image")) << r.err;
    r = run({"convert", path("a.exr"), path("x.jpg")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, ".exr, .hdr, .pfm, .png")) << r.err;
    r = run({"convert", path("a.exr"), path("a.exr")});
    EXPECT_EQ(r.code, 2);
    r = run({"convert", path("missing.exr"), path("y.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "missing.exr")) << r.err;
}

// An EXR with render metadata of the kind a renderer adds (written with OpenEXR directly).
void write_exr_with_metadata(const std::string& file, const Image& img) {
    Imf::Header header(img.width(), img.height());
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    header.insert("spp", Imf::IntAttribute(64));
    header.insert("seed", Imf::StringAttribute("1234"));
    header.insert("seconds", Imf::DoubleAttribute(2.5));
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(const_cast<float*>(img.data()));
    const size_t xs = sizeof(Rgb), ys = sizeof(Rgb) * size_t(img.width());
    for (int c = 0; c < 3; ++c) fb.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, base + size_t(c) * sizeof(float), xs, ys));
    Imf::OutputFile out(file.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(img.height());
}

TEST_F(Lab, InfoShowsSizeChannelsMetadataMeansAndNonFiniteCounts) {
    Image img(4, 2, Rgb(0.5f, 1.0f, 2.0f));
    img.at(1, 0).x = NAN;
    img.at(2, 1).z = INFINITY;
    write_exr_with_metadata(path("m.exr"), img);
    CliResult r = run({"info", path("m.exr")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "4x2 OpenEXR")) << r.out;
    EXPECT_TRUE(contains(r.out, "B (float), G (float), R (float)")) << r.out;
    EXPECT_TRUE(contains(r.out, "spp: 64 [int]")) << r.out;
    EXPECT_TRUE(contains(r.out, "seed: 1234 [string]")) << r.out;
    EXPECT_TRUE(contains(r.out, "seconds: 2.5 [double]")) << r.out;
    EXPECT_TRUE(contains(r.out, "1 NaN, 1 Inf")) << r.out;
    r = run({"info", "--json", path("m.exr")});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["width"], 4);
    EXPECT_EQ(j["nan"], 1);
    EXPECT_EQ(j["inf"], 1);
    EXPECT_DOUBLE_EQ(j["mean"][0].get<double>(), 0.5);  // the NaN left out
    EXPECT_DOUBLE_EQ(j["mean"][2].get<double>(), 2.0);  // the Inf left out
    EXPECT_EQ(j["attributes"]["spp"], "64 [int]");
    // Every format; a PNG's 8-bit codes.
    write_image(test_image(5, 3), path("t.pfm"));
    write_image(test_image(5, 3), path("t.hdr"));
    write_png8(Image8{2, 1, {0, 10, 20, 30, 40, 50}}, path("t.png"));
    r = run({"info", path("t.pfm"), path("t.hdr"), path("t.png")});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "t.pfm: 5x3 PFM")) << r.out;
    EXPECT_TRUE(contains(r.out, "byte order: little-endian")) << r.out;
    EXPECT_TRUE(contains(r.out, "t.hdr: 5x3 Radiance RGBE")) << r.out;
    EXPECT_TRUE(contains(r.out, "FORMAT: 32-bit_rle_rgbe")) << r.out;
    EXPECT_TRUE(contains(r.out, "t.png: 2x1 PNG")) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("mean +15 +25 +35"))) << r.out;
    r = run({"info", path("nothing.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "nothing.exr")) << r.err;
}

}  // namespace
}  // namespace pathlab::test
