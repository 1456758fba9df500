// Numbers, outputs and sizes that used to go wrong silently (the hardening issue): seeds and
// resolutions that wrapped, thread counts that exhausted memory, outputs that overwrote the
// inputs, films too large for memory, 32-bit sample counters.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "core/memory.hpp"
#include "render/film.hpp"

namespace pathlab::test {
namespace {

namespace fs = std::filesystem;

class CliLimits : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-limits-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    static std::string read(const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    }
    fs::path dir_;
};

TEST_F(CliLimits, SeedsOutOfRangeAreUsageErrorsNotWrappedNumbers) {
    for (const char* seed : {"-1", "18446744073709551616", "1e23", "12abc", "", " 5"}) {
        const CliResult r = run({"-s", "0", "--resolution", "4x4", "--spp", "1", "--seed", seed, "-q", "-o", path("s.pfm")});
        EXPECT_EQ(r.code, 2) << "--seed '" << seed << "'";
        EXPECT_TRUE(contains(r.err, "invalid --seed")) << r.err;
        EXPECT_FALSE(fs::exists(path("s.pfm")));
    }
    EXPECT_EQ(run({"-s", "0", "--resolution", "4x4", "--spp", "1", "--seed", "18446744073709551615", "-q", "-o", path("s.pfm")}).code, 0);
    EXPECT_EQ(run({"check", "-a", "1", "--references", path(""), "--seed", "-1"}).code, 2);
}

TEST_F(CliLimits, ResolutionsOutOfRangeAreUsageErrors) {
    for (const char* res : {"4294967312x16", "16x4294967312", "32769x16", "0x16", "-16x16", "16x16x", "16 x16", "1e3x16"}) {
        const CliResult r = run({"-s", "0", "--resolution", res, "--spp", "1", "-q", "-o", path("r.pfm")});
        EXPECT_EQ(r.code, 2) << res << ": " << r.err;
        EXPECT_TRUE(contains(r.err, "invalid --resolution")) << r.err;
    }
}

TEST_F(CliLimits, HugeThreadCountsAreCappedWithAMessage) {
    const CliResult r = run({"-s", "0", "--resolution", "8x8", "--spp", "1", "--threads", "2147483647", "-q", "-o", path("t.pfm")});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "--threads 2147483647 is more than 8 x the")) << r.err;
    EXPECT_EQ(run({"-s", "0", "--resolution", "8x8", "--spp", "1", "--threads", "-3", "-q", "-o", path("t.pfm")}).code, 2);
}

TEST_F(CliLimits, OutputsNeverOverwriteInputsOrEachOther) {
    const std::string scene = path("scene.xml");
    const std::string text = "<scene version=\"3.0.0\"><shape type=\"rectangle\"/><emitter type=\"constant\"/></scene>\n";
    std::ofstream(scene) << text;
    // --stats onto the scene file, through another spelling of its path too.
    for (const std::string& stats : {scene, (dir_ / "." / "scene.xml").string()}) {
        const CliResult r = run({"-s", scene, "--resolution", "4x4", "--spp", "1", "-q", "-o", path("a.exr"), "--stats", stats});
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_TRUE(contains(r.err, "is the scene file")) << r.err;
        EXPECT_EQ(read(scene), text);
    }
    // --stats onto the image, and one image twice.
    CliResult r = run({"-s", "0", "--resolution", "4x4", "--spp", "1", "-q", "-o", path("a.exr"), "--stats", path("a.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "is also the output")) << r.err;
    r = run({"-s", "0", "--resolution", "4x4", "--spp", "1", "-q", "-o", path("a.exr"), "-o", path("a.exr")});
    EXPECT_EQ(r.code, 2);
    EXPECT_FALSE(fs::exists(path("a.exr")));
    // -o onto an image the scene reads (a bitmap texture beside it), and --ic-records onto it.
    ASSERT_EQ(run({"-s", "0", "--resolution", "4x4", "--spp", "1", "-q", "-o", path("wood.pfm")}).code, 0);
    const std::string wood = read(path("wood.pfm"));
    const std::string textured = path("textured.xml");
    std::ofstream(textured) << "<scene version=\"3.0.0\"><shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" "
                               "name=\"reflectance\"><string name=\"filename\" value=\"wood.pfm\"/></texture></bsdf></shape>"
                               "<emitter type=\"constant\"/></scene>\n";
    for (const std::vector<std::string>& onto : {std::vector<std::string>{"-o", path("wood.pfm")},
                                                 std::vector<std::string>{"-a", "ic", "-o", path("b.pfm"), "--ic-records", path("wood.pfm")}}) {
        std::vector<std::string> args{"-s", textured, "--resolution", "4x4", "--spp", "1", "-q"};
        args.insert(args.end(), onto.begin(), onto.end());
        r = run(args);
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_TRUE(contains(r.err, "is a file textured.xml reads")) << r.err;
        EXPECT_EQ(read(path("wood.pfm")), wood);
    }
    // check --json onto a reference, before it is read.
    fs::create_directories(path("refs"));
    ASSERT_EQ(run({"-s", "0", "--resolution", "8x8", "--spp", "1", "-q", "-o", path("refs/0.pfm")}).code, 0);
    const std::string ref = read(path("refs/0.pfm"));
    r = run({"check", "-a", "1", "-s", "0", "--references", path("refs"), "--spp", "1", "--json", path("refs/0.pfm")});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "is a file of --references")) << r.err;
    EXPECT_EQ(read(path("refs/0.pfm")), ref);
}


// A film too large for memory is refused before it is allocated, saying how much it needs;
// the other scenes of the command still render.
TEST_F(CliLimits, AFilmTooLargeForMemoryFailsThatSceneOnly) {
    if (available_memory() == 0 || available_memory() > (uint64_t(90) << 30))
        GTEST_SKIP() << "this machine could allocate a 32768x32768 film (or does not say how much memory it has)";
    const std::string huge = path("huge.xml");
    std::ofstream(huge) << "<scene version=\"3.0.0\"><sensor type=\"perspective\"><film type=\"hdrfilm\">"
                           "<integer name=\"width\" value=\"32768\"/><integer name=\"height\" value=\"32768\"/></film></sensor>"
                           "<shape type=\"rectangle\"/></scene>\n";
    const CliResult r = run({"-s", "0," + huge, "--spp", "1", "-q", "-o", path("{scene}.pfm")});
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(contains(r.err, "a 32768x32768 render needs 208.0 GiB of memory")) << r.err;
    EXPECT_TRUE(fs::exists(path("point-diffuse.pfm"))) << "the other scene must still render";
    EXPECT_FALSE(fs::exists(path("huge.pfm")));
    // check renders at its references' size: a --resolution of another size (here one too large
    // for memory) is refused before anything renders.
    const CliResult c = run({"check", "-a", "1", "-s", "0,1", "--references", std::string(PATHLAB_SHARED_DIR) + "/npgr010-refs/direct",
                             "--spp", "1", "--resolution", "32768x32768"});
    EXPECT_EQ(c.code, 2);
    EXPECT_TRUE(contains(c.err, "is 512x512, but --resolution asks for 32768x32768")) << c.err;
}

// Photon counts and strategy images that cannot fit are refused before they are allocated, with
// the figure and the option to lower (they ran for minutes and ended in std::bad_alloc): the
// photons per light path come from a pilot of 256 light paths; nothing is written.
TEST_F(CliLimits, PhotonMapsAndStrategyImagesTooLargeForMemoryAreRefusedUpFront) {
    if (available_memory() == 0 || available_memory() > (uint64_t(300) << 30))
        GTEST_SKIP() << "this machine could hold 10^10 light paths' photons or 2048x2048 images of 594 strategies (or does not say "
                        "how much memory it has)";
    for (const char* a : {"pm", "sppm"}) {
        const CliResult r = run({"-s", "2", "-a", a, "--photons", "10000000000", "--resolution", "8x8", "--spp", "1", "-q", "-o", path("p.pfm")});
        EXPECT_EQ(r.code, 1) << a << ": " << r.err;
        EXPECT_TRUE(contains(r.err, std::string(a) + "'s 10000000000 light paths (about ")) << r.err;
        EXPECT_TRUE(contains(r.err, "GiB is available: lower --photons (about ")) << r.err;
        EXPECT_FALSE(fs::exists(path("p.pfm")));
    }
    const CliResult s = run({"-s", "2", "-a", "bdpt", "--strategies", path("st"), "--strategies-depth", "32", "--resolution", "2048x2048",
                             "--spp", "1", "-q", "-o", path("b.pfm")});
    EXPECT_EQ(s.code, 1) << s.err;
    EXPECT_TRUE(contains(s.err, "--strategies images of paths up to 32 bounces (594 strategies")) << s.err;
    EXPECT_TRUE(contains(s.err, ": lower --strategies-depth (at most ")) << s.err;
    EXPECT_FALSE(fs::exists(path("b.pfm")));
    // what fits still renders
    EXPECT_EQ(run({"-s", "2", "-a", "pm", "--photons", "2000", "--resolution", "8x8", "--spp", "1", "-q", "-o", path("p.pfm")}).code, 0);
}

// The memory a render may take is also bounded by its address-space limit (ulimit -v, as batch
// systems set it) and its cgroup: under a 3 GB limit, 20 million light paths of pm (5.4 GiB of
// photons) are refused up front; they ran 31 s and ended in std::bad_alloc when only the
// machine's free memory was read.
TEST_F(CliLimits, AnAddressSpaceLimitBoundsTheMemoryCheck) {
    const std::string err = path("err.txt");
    const std::string command = fmt::format("(ulimit -v 3000000; timeout -s KILL 120 {} 1 -a pm --photons 20000000 --resolution 16x16 --spp 1 -q -o {}) 2> {}",
                                            PATHLAB_BINARY, path("pm.pfm"), err);
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal";
    EXPECT_EQ(WEXITSTATUS(status), 1);
    std::ifstream in(err);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(contains(text, "pm's 20000000 light paths (about ")) << text;
    EXPECT_TRUE(contains(text, "GiB is available: lower --photons")) << text;
    EXPECT_FALSE(fs::exists(path("pm.pfm")));
}

// A named pipe where a file is read (an image, a checkpoint, a mapping, a spectrum) is refused
// as not a regular file; opening one waited for a writer for ever. Run under `timeout`, so that
// a regression fails (exit 124) rather than hangs.
TEST_F(CliLimits, NamedPipesAreRefusedNotWaitedOn) {
    for (const char* name : {"p.exr", "p.ckpt", "p.map", "p.spd"}) ASSERT_EQ(::mkfifo(path(name).c_str(), 0600), 0) << name;
    ASSERT_EQ(run({"1", "--spp", "1", "--resolution", "4x4", "-q", "-o", path("a.exr")}).code, 0);
    std::ofstream(path("s.xml")) << "<scene version=\"3.0.0\"><bsdf type=\"diffuse\" id=\"m\"><spectrum name=\"reflectance\" "
                                    "filename=\"p.spd\"/></bsdf><shape type=\"sphere\"><ref id=\"m\"/></shape><emitter type=\"constant\"/></scene>";
    const std::string bin = PATHLAB_BINARY;
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"info " + path("p.exr"), "p.exr: not a regular file"},
        {"info " + path("p.ckpt"), "p.ckpt"},
        {"merge " + path("m.exr") + " " + path("a.exr") + " " + path("p.exr"), "p.exr: not a regular file"},
        {"merge " + path("m.exr") + " " + path("a.exr") + " " + path("p.ckpt"), "p.ckpt"},
        {"check 1 -a pt-mis --references " + dir_.string() + " --mapping " + path("p.map"), "p.map: cannot read the mapping file: not a regular file"},
        {path("s.xml") + " --resolution 4x4 --spp 1 -q -o " + path("s.exr"), "p.spd': not a regular file"},
    };
    for (const auto& [args, message] : cases) {
        const int status = std::system(fmt::format("timeout 20 {} {} 2> {}", bin, args, path("err.txt")).c_str());
        ASSERT_TRUE(WIFEXITED(status)) << args;
        EXPECT_EQ(WEXITSTATUS(status), 2) << args << " (124: it waited on the pipe)";
        std::ifstream in(path("err.txt"));
        const std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_TRUE(contains(err, message)) << args << ": " << err;
    }
}

// --strategies writes at most 32 bounces (594 strategies, 2,376 files): 10^6 with unlimited
// paths (1024 bounces, 526,850 strategies) grew past 13 GiB on 8x8 pixels and wrote millions of
// files; it is refused before anything renders. A path limit below it still caps the depth.
TEST_F(CliLimits, StrategyImagesDeeperThan32BouncesAreRefused) {
    const CliResult u = run({"-s", "2", "-a", "bdpt", "--strategies", path("st"), "--strategies-depth", "1000000", "--resolution", "8x8",
                             "--spp", "1", "-q", "-o", path("b.pfm")});
    EXPECT_EQ(u.code, 2) << u.err;
    EXPECT_TRUE(contains(u.err, "--strategies images of paths up to 1024 bounces would be 526850 strategies and 2107400 files; at most "
                                "32 bounces are written (594 strategies): lower --strategies-depth or give --max-depth (paths are unlimited here)")) << u.err;
    EXPECT_FALSE(fs::exists(path("b.pfm")));
    EXPECT_FALSE(fs::exists(path("st")));
    const CliResult m = run({"-s", "2", "-a", "bdpt", "--strategies", path("st"), "--strategies-depth", "40", "--max-depth", "33",
                             "--resolution", "8x8", "--spp", "1", "-q", "-o", path("b.pfm")});
    EXPECT_EQ(m.code, 2) << m.err;
    EXPECT_TRUE(contains(m.err, "up to 33 bounces would be 629 strategies")) << m.err;
    EXPECT_TRUE(contains(m.err, "lower --strategies-depth or --max-depth")) << m.err;
    const CliResult ok = run({"-s", "2", "-a", "bdpt", "--strategies", path("st"), "--strategies-depth", "1000000", "--max-depth", "2",
                              "--resolution", "8x8", "--spp", "1", "-q", "-o", path("b.pfm")});
    EXPECT_EQ(ok.code, 0) << ok.err;
    EXPECT_TRUE(fs::exists(path("st/n2-s0-t4-weighted.exr")));
    EXPECT_FALSE(fs::exists(path("st/n3-s0-t5-weighted.exr")));
}

// Sample counts are 64-bit: a pixel past 2^32 samples keeps counting and averaging.
TEST(FilmCounters, CountsPassTwoToThe32) {
    const uint64_t n = (uint64_t(1) << 32) - 1;
    Film film = Film::from_sums(1, 1, {Vec3d(double(n))}, {Vec3d(double(n))}, {n});
    film.add(0, Rgb(1.0f));
    film.add(0, Rgb(1.0f));
    EXPECT_EQ(film.count(0), n + 2);
    EXPECT_EQ(film.mean()[0], Rgb(1.0f));
}

}  // namespace
}  // namespace pathlab::test
