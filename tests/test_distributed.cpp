// Rendering beyond one process (docs/distributed.md): the film's exact sums, pass sets, the
// checkpoint file, resume, merge, and MPI ranks (through mpirun, as CI runs it: as root, two
// ranks oversubscribed on one machine).
#include <gtest/gtest.h>
#include <xxhash.h>

#include <cstddef>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "fake_tev.hpp"
#include "image/image_io.hpp"
#include "integrators/integrators.hpp"
#include "job/checkpoint.hpp"
#include "job/pass_set.hpp"
#include "job/render_job.hpp"
#include "render/exact_sum.hpp"

namespace pathlab::test {
namespace {

namespace fs = std::filesystem;

// ---- the exact, order-independent sums -----------------------------------------------------

struct Acc {
    int64_t limbs[exact::kBins] = {};
    uint8_t top = 0;
    void add(double x) { exact::deposit(limbs, top, x); }
    bool operator==(const Acc& o) const { return top == o.top && std::memcmp(limbs, o.limbs, sizeof limbs) == 0; }
};

// Values over 40 orders of magnitude, of both signs, squares of floats as the film adds them.
std::vector<double> wide_values(uint32_t seed, size_t n) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> exponent(-60, 70), mantissa(1, 2);
    std::vector<double> v;
    for (size_t i = 0; i < n; ++i) {
        const float f = float(std::ldexp(mantissa(rng), int(exponent(rng))));
        v.push_back(i % 3 == 0 ? double(f) * double(f) : (i % 7 == 0 ? -double(f) : double(f)));
    }
    return v;
}

TEST(ExactSum, AnyOrderAndAnyGroupingGiveTheSameBits) {
    const std::vector<double> v = wide_values(1, 2000);
    Acc forward, backward, shuffled;
    for (double x : v) forward.add(x);
    for (auto it = v.rbegin(); it != v.rend(); ++it) backward.add(*it);
    std::vector<double> s = v;
    std::shuffle(s.begin(), s.end(), std::mt19937(5));
    for (double x : s) shuffled.add(x);
    EXPECT_TRUE(forward == backward);
    EXPECT_TRUE(forward == shuffled);
    // Three parts summed apart and merged, in two orders.
    Acc parts[3];
    for (size_t i = 0; i < v.size(); ++i) parts[i * 3 / v.size()].add(v[i]);
    Acc ab = parts[0], cb = parts[2];
    exact::merge(ab.limbs, ab.top, parts[1].limbs, parts[1].top);
    exact::merge(ab.limbs, ab.top, parts[2].limbs, parts[2].top);
    exact::merge(cb.limbs, cb.top, parts[1].limbs, parts[1].top);
    exact::merge(cb.limbs, cb.top, parts[0].limbs, parts[0].top);
    EXPECT_TRUE(ab == forward);
    EXPECT_TRUE(cb == forward);
    // For contrast, plain double addition depends on the order: 1 + 2^53 - 2^53 is 0 forwards
    // and 1 backwards; the exact sum is 1 either way.
    const std::vector<double> hard = {1.0, std::ldexp(1.0, 53), -std::ldexp(1.0, 53)};
    Acc m1, m2;
    double f = 0, b = 0;
    for (double x : hard) m1.add(x), f += x;
    for (auto it = hard.rbegin(); it != hard.rend(); ++it) m2.add(*it), b += *it;
    EXPECT_TRUE(m1 == m2);
    EXPECT_EQ(exact::value(m1.limbs, m1.top), 1.0);
    EXPECT_NE(f, b) << "the values should be hard enough for double addition";
}

TEST(ExactSum, ReadsOutTheCorrectlyRoundedSum) {
    // Sums whose exact value is known: 1 + 2^-60 (60 bits apart, inside the window) read out as the
    // double nearest to it, 1; 2^-30 + 2^-31 + 3 exactly; large and tiny values cancel exactly.
    Acc a;
    a.add(1.0), a.add(std::ldexp(1.0, -60));
    EXPECT_EQ(exact::value(a.limbs, a.top), 1.0);
    Acc b;
    b.add(std::ldexp(1.0, -30)), b.add(3.0), b.add(std::ldexp(1.0, -31));
    EXPECT_EQ(exact::value(b.limbs, b.top), 3.0 + std::ldexp(1.5, -30));
    Acc c;
    c.add(1e30), c.add(0.25), c.add(-1e30);
    EXPECT_EQ(exact::value(c.limbs, c.top), 0.0) << "0.25 is below 2^-60 of 1e30: dropped, as documented";
    Acc d;
    d.add(1e10), d.add(0.25), d.add(-1e10);
    EXPECT_EQ(exact::value(d.limbs, d.top), 0.25);
    Acc e;  // many equal floats: exact
    for (int i = 0; i < 100000; ++i) e.add(0.1f);
    EXPECT_EQ(exact::value(e.limbs, e.top), 100000.0 * double(0.1f));
    Acc empty;
    EXPECT_EQ(exact::value(empty.limbs, empty.top), 0.0);
}

// ---- pass sets ---------------------------------------------------------------------------

TEST(PassSet, SetOperationsPartsAndText) {
    PassSet s;
    s.insert(10, 20), s.insert(0, 5), s.insert(5, 8), s.insert(19, 25);
    EXPECT_EQ(s.to_string(), "0-7,10-24");
    EXPECT_EQ(s.count(), 23u);
    EXPECT_EQ(PassSet::parse(s.to_string()), s);
    EXPECT_EQ(PassSet::range(0, 30).minus(s).to_string(), "8-9,25-29");
    EXPECT_EQ(s.first(9).to_string(), "0-7,10");
    // Parts: contiguous in order, sizes 8, 8, 7, together the set.
    PassSet all;
    uint64_t sizes[3];
    for (int k = 0; k < 3; ++k) {
        const PassSet p = s.part(k, 3);
        sizes[k] = p.count();
        EXPECT_FALSE(all.intersects(p));
        all.insert(p);
    }
    EXPECT_EQ(all, s);
    EXPECT_EQ(sizes[0], 8u);
    EXPECT_EQ(sizes[1], 8u);
    EXPECT_EQ(sizes[2], 7u);
    EXPECT_EQ(s.part(0, 3).to_string(), "0-7");
    EXPECT_EQ(s.part(2, 3).to_string(), "18-24");
    EXPECT_TRUE(PassSet::range(0, 30).contains(s));
    EXPECT_FALSE(s.contains(PassSet::range(7, 11)));
    for (const char* bad : {"1-", "3-2", "0-5,4-9", "0-5,6", "a", "1,,2", "1,"}) EXPECT_FALSE(PassSet::parse(bad)) << bad;
    EXPECT_EQ(PassSet::parse("")->count(), 0u);
}

// ---- films split into pass ranges add up to the one-shot film ------------------------------

RenderJob small_job(const std::string& algorithm, int scene = 3) {
    JobRequest r;
    r.algorithm = algorithm;
    r.width = 12, r.height = 10, r.spp = 1, r.seed = 7;
    return RenderJob(scene, r);
}

// Passes [first, first + n) into a new film.
Film render_range(RenderJob& job, uint64_t first, uint64_t n) {
    job.settings.first_sample = first;
    job.settings.spp = n;
    return job.run().film;
}

TEST(DistributedFilm, PassRangesRenderedApartMergeToTheOneShotFilmBitForBit) {
    for (const char* a : {"pt-mis", "lt", "bdpt", "sppm", "vcm"}) {
        RenderJob job = small_job(a);
        const Film whole = render_range(job, 0, 7);
        Film parts = render_range(job, 4, 3);
        parts.merge(render_range(job, 0, 2));
        parts.merge(render_range(job, 2, 2));
        EXPECT_TRUE(parts.identical(whole)) << a;
        // The images too (what an EXR stores).
        EXPECT_EQ(std::memcmp(parts.mean().data(), whole.mean().data(), whole.pixel_count() * sizeof(Rgb)), 0) << a;
        EXPECT_EQ(std::memcmp(parts.standard_error().data(), whole.standard_error().data(), whole.pixel_count() * sizeof(Rgb)), 0) << a;
    }
}

// ---- command-line helpers ----------------------------------------------------------------

class Distributed : public testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / fmt::format("pathlab_distributed_{}_{}", ::getpid(),
                                                       testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    // Runs a shell command; its exit code (128 + signal when killed), stderr into `err`.
    int shell(const std::string& command, std::string* err = nullptr) const {
        const std::string err_path = path("stderr.txt");
        const int status = std::system((command + " 2> " + err_path).c_str());
        if (err) {
            std::ifstream in(err_path);
            err->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        }
        if (WIFEXITED(status)) return WEXITSTATUS(status);
        return 128 + WTERMSIG(status);
    }
    // mpirun as CI runs it: as root, two ranks oversubscribed on one machine.
    static std::string mpirun(int ranks) {
        return fmt::format("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 120 mpirun --allow-run-as-root --oversubscribe "
                           "-n {} {}",
                           ranks, PATHLAB_BINARY);
    }
    // Renders one small scene per integrator with one process of 2 threads and 2 ranks of 1
    // thread, and expects the same bytes (defined below).
    void expect_two_ranks_equal_one_process(const std::vector<std::string>& algorithms, const std::string& flags);

    fs::path dir_;
};

struct ExrRender {
    Image mean, standard_error;
    std::map<std::string, std::string> attributes;
};

ExrRender read_render(const std::string& path) {
    ExrExtras extras;
    ExrRender r;
    r.mean = read_exr(path, extras);
    for (auto& [name, image] : extras.layers)
        if (name == "stderr") r.standard_error = std::move(image);
    r.attributes.insert(extras.attributes.begin(), extras.attributes.end());
    return r;
}

// Bit for bit: the mean and the standard errors.
::testing::AssertionResult same_render(const std::string& a, const std::string& b) {
    const ExrRender x = read_render(a), y = read_render(b);
    if (x.mean.pixel_count() != y.mean.pixel_count() || x.mean.pixel_count() == 0) return ::testing::AssertionFailure() << "sizes differ";
    const size_t bytes = x.mean.pixel_count() * sizeof(Rgb);
    if (x.standard_error.pixel_count() != x.mean.pixel_count()) return ::testing::AssertionFailure() << a << " has no stderr layer";
    size_t differ = 0;
    for (size_t i = 0; i < x.mean.pixel_count(); ++i)
        differ += std::memcmp(&x.mean[i], &y.mean[i], sizeof(Rgb)) != 0 || std::memcmp(&x.standard_error[i], &y.standard_error[i], sizeof(Rgb)) != 0;
    if (differ) return ::testing::AssertionFailure() << a << " and " << b << ": " << differ << " pixels differ";
    (void)bytes;
    return ::testing::AssertionSuccess();
}

std::string file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

const std::string kSmall = "--scene 3 --resolution 16x12 --seed 5 -q";

// ---- checkpoints and resume --------------------------------------------------------------

TEST_F(Distributed, EveryExrCarriesItsStandardErrorsAndWhatItIsOf) {
    ASSERT_EQ(run({"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "6", "-o", path("a.exr")}).code, 0);
    const ExrRender r = read_render(path("a.exr"));
    EXPECT_EQ(r.attributes.at("pathlab:spp"), "6");
    EXPECT_EQ(r.attributes.at("pathlab:seed"), "5");
    EXPECT_EQ(r.attributes.at("pathlab:firstSample"), "0");
    EXPECT_EQ(r.attributes.at("pathlab:passes"), "0-5");
    EXPECT_EQ(r.attributes.at("pathlab:integrator"), "pt-mis");
    EXPECT_EQ(r.attributes.at("pathlab:sceneHash").size(), 16u);
    ASSERT_EQ(r.standard_error.pixel_count(), r.mean.pixel_count());
    double se = 0;
    for (size_t i = 0; i < r.standard_error.pixel_count(); ++i) se += r.standard_error[i].x;
    EXPECT_GT(se, 0);
}

TEST_F(Distributed, ResumedRenderEqualsTheUninterruptedOneBitForBit) {
    for (const char* a : {"pt-mis", "sppm", "ic"}) {
        const std::string common = fmt::format("{} -a {} --resolution 16x12 --seed 5 -q", "--scene 3", a);
        (void)common;
        const std::vector<std::string> base = {"--scene", "3", "-a", a, "--resolution", "16x12", "--seed", "5", "-q"};
        auto with = [&](std::vector<std::string> extra) {
            std::vector<std::string> args = base;
            args.insert(args.end(), extra.begin(), extra.end());
            return run(args);
        };
        fs::remove(path("c.ckpt"));
        ASSERT_EQ(with({"--spp", "9", "-o", path("whole.exr")}).code, 0);
        ASSERT_EQ(with({"--spp", "4", "--checkpoint", path("c.ckpt"), "-o", path("part.exr")}).code, 0) << a;
        EXPECT_EQ(read_checkpoint_info(path("c.ckpt")).passes.to_string(), "0-3");
        const CliResult r = with({"--spp", "9", "--resume", path("c.ckpt"), "-o", path("resumed.exr")});
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_TRUE(same_render(path("whole.exr"), path("resumed.exr"))) << a;
        EXPECT_EQ(read_checkpoint_info(path("c.ckpt")).passes.to_string(), "0-8") << "resuming goes on checkpointing to the same file";
    }
}

// `pathlab --resume FILE` alone continues the render: the checkpoint records its command (the
// scene, the estimator, the options given); options given beside it replace the recorded ones,
// and what then differs from the checkpoint's render is refused as for any --resume.
TEST_F(Distributed, ResumeWithoutTheCommandLineContinuesTheRender) {
    const std::vector<std::string> base = {"--scene", "3", "-a", "sppm", "--resolution", "16x12", "--seed", "5", "-q"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = base;
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args);
    };
    ASSERT_EQ(with({"--spp", "9", "-o", path("whole.exr")}).code, 0);
    ASSERT_EQ(with({"--spp", "4", "--checkpoint", path("c.ckpt"), "-o", path("part.exr")}).code, 0);
    const CliResult info = run({"info", path("c.ckpt")});
    EXPECT_TRUE(contains(info.out, "pathlab:command: pathlab render ceiling-glossy --algorithm sppm --spp 4 --resolution 16x12 --seed 5 "
                                   "--output " + path("part.exr") + " --quiet"))
        << info.out;
    // Another seed beside it: not this checkpoint's render.
    const CliResult seed = run({"--resume", path("c.ckpt"), "--spp", "9", "--seed", "6", "-o", path("b.exr")});
    EXPECT_EQ(seed.code, 2);
    EXPECT_TRUE(contains(seed.err, "seed: 5 in the checkpoint, 6 in this render")) << seed.err;
    EXPECT_EQ(read_checkpoint_info(path("c.ckpt")).passes.to_string(), "0-3");
    // More samples: the recorded output becomes the render never interrupted, byte for byte.
    const CliResult more = run({"--resume", path("c.ckpt"), "--spp", "9"});
    ASSERT_EQ(more.code, 0) << more.err;
    EXPECT_TRUE(same_render(path("whole.exr"), path("part.exr")));
    EXPECT_EQ(read_checkpoint_info(path("c.ckpt")).passes.to_string(), "0-8");
    // The checkpoint now records --spp 9; another output beside it (and `render`, its long form).
    ASSERT_EQ(run({"render", "--resume", path("c.ckpt"), "-o", path("resumed.exr")}).code, 0);
    EXPECT_TRUE(same_render(path("whole.exr"), path("resumed.exr")));
    const CliResult fewer = run({"--resume", path("c.ckpt"), "--spp", "2"});
    EXPECT_EQ(fewer.code, 2);
    EXPECT_TRUE(contains(fewer.err, "raise --spp")) << fewer.err;
    // A copy resumed checkpoints to itself, not to the file its first run wrote.
    fs::copy_file(path("c.ckpt"), path("copy.ckpt"));
    const std::string original = file_bytes(path("c.ckpt"));
    ASSERT_EQ(run({"--resume", path("copy.ckpt"), "--spp", "12", "-o", path("copy.exr")}).code, 0);
    EXPECT_EQ(read_checkpoint_info(path("copy.ckpt")).passes.to_string(), "0-11");
    EXPECT_TRUE(file_bytes(path("c.ckpt")) == original) << "the first run's checkpoint is left alone";
    // A file that is not a checkpoint is named.
    const CliResult bad = run({"--resume", path("whole.exr")});
    EXPECT_EQ(bad.code, 2);
    EXPECT_TRUE(contains(bad.err, path("whole.exr") + ": not a pathlab checkpoint")) << bad.err;
}

TEST_F(Distributed, CheckpointOfAnotherRenderIsRefusedSayingWhatDiffers) {
    ASSERT_EQ(run({"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "2", "--checkpoint", path("c.ckpt"), "-o",
                   path("a.exr")})
                  .code,
              0);
    const std::string before = file_bytes(path("c.ckpt"));
    // `info` says which render a checkpoint holds, as it says it of an EXR.
    const CliResult info = run({"info", path("c.ckpt")});
    EXPECT_EQ(info.code, 0) << info.err;
    for (const char* line : {"16x12 pathlab checkpoint", "pathlab:integrator: pt-mis", "pathlab:seed: 5", "pathlab:spp: 2", "pathlab:passes: 0-1"})
        EXPECT_TRUE(contains(info.out, line)) << line << " in\n" << info.out;
    const CliResult other_scene =
        run({"--scene", "4", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "4", "--resume", path("c.ckpt"), "-o", path("b.exr")});
    EXPECT_EQ(other_scene.code, 2);
    EXPECT_TRUE(contains(other_scene.err, "is a checkpoint of another render")) << other_scene.err;
    EXPECT_TRUE(contains(other_scene.err, "scene hash:")) << other_scene.err;
    const CliResult other_seed =
        run({"--scene", "3", "--resolution", "16x12", "--seed", "6", "-q", "--spp", "4", "--resume", path("c.ckpt"), "-o", path("b.exr")});
    EXPECT_EQ(other_seed.code, 2);
    EXPECT_TRUE(contains(other_seed.err, "seed: 5 in the checkpoint, 6 in this render")) << other_seed.err;
    const CliResult other_algorithm = run({"--scene", "3", "-a", "lt", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "4", "--resume",
                                           path("c.ckpt"), "-o", path("b.exr")});
    EXPECT_EQ(other_algorithm.code, 2);
    EXPECT_TRUE(contains(other_algorithm.err, "integrator: pt-mis in the checkpoint, lt in this render")) << other_algorithm.err;
    const CliResult fewer =
        run({"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "1", "--resume", path("c.ckpt"), "-o", path("b.exr")});
    EXPECT_EQ(fewer.code, 2);
    EXPECT_TRUE(contains(fewer.err, "raise --spp")) << fewer.err;
    EXPECT_TRUE(file_bytes(path("c.ckpt")) == before) << "a refused checkpoint is left as it was";
    EXPECT_FALSE(fs::exists(path("b.exr")));
    // A new render does not overwrite an existing checkpoint.
    const CliResult fresh =
        run({"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "2", "--checkpoint", path("c.ckpt"), "-o", path("b.exr")});
    EXPECT_EQ(fresh.code, 2);
    EXPECT_TRUE(contains(fresh.err, "--resume")) << fresh.err;
}

TEST_F(Distributed, TruncatedOrCorruptedCheckpointIsRefusedAndKept) {
    ASSERT_EQ(run({"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "2", "--checkpoint", path("c.ckpt"), "-o",
                   path("a.exr")})
                  .code,
              0);
    const std::string good = file_bytes(path("c.ckpt"));
    struct Damage {
        const char* what;
        std::string bytes;
        const char* message;
    };
    std::string flipped = good;
    flipped[good.size() / 2] ^= 0x10;  // one bit in the pixels
    std::string header = good;
    header[20] ^= 0x01;  // one bit in the header text
    const std::vector<Damage> damages = {{"truncated", good.substr(0, good.size() - 100), "truncated"},
                                         {"cut in the header", good.substr(0, 30), "truncated"},
                                         {"a bit flipped", flipped, "corrupted"},
                                         {"a header bit flipped", header, ""},
                                         {"empty", "", "not a pathlab checkpoint"},
                                         {"not one", std::string(4000, 'x'), "not a pathlab checkpoint"}};
    for (const Damage& d : damages) {
        std::ofstream(path("bad.ckpt"), std::ios::binary) << d.bytes;
        const CliResult r = run({"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "4", "--resume", path("bad.ckpt"), "-o",
                                 path("b.exr")});
        EXPECT_EQ(r.code, 2) << d.what << ": " << r.err;
        EXPECT_TRUE(contains(r.err, path("bad.ckpt"))) << d.what << ": " << r.err;
        EXPECT_TRUE(contains(r.err, d.message)) << d.what << ": " << r.err;
        EXPECT_TRUE(file_bytes(path("bad.ckpt")) == d.bytes) << d.what << ": never overwritten";
        EXPECT_FALSE(fs::exists(path("b.exr")));
        EXPECT_EQ(run({"info", path("bad.ckpt")}).code, 2) << d.what;
    }
    EXPECT_THROW(read_checkpoint(path("missing.ckpt")), CheckpointError);

    // Forged: a pixel's sums changed and the checksum recomputed (the checksum alone accepted
    // them): the first pixel's count raised past the passes, and its first channel's sum of
    // squares zeroed while its sum is not.
    uint32_t h = 0;
    std::memcpy(&h, good.data() + 12, 4);
    const size_t first_pixel = 16 + h + 8;
    const size_t count_at = first_pixel + offsetof(PixelSums, count), sumsq_at = first_pixel + offsetof(PixelSums, sumsq);
    const auto forged = [&](size_t at, const std::string& bytes) {
        std::string f = good;
        f.replace(at, bytes.size(), bytes);
        const uint64_t checksum = XXH3_64bits(f.data(), f.size() - 8);
        std::memcpy(f.data() + f.size() - 8, &checksum, 8);
        return f;
    };
    const uint64_t many = 1000;
    // The header's time spent: "nan" over its value, the same length (a NaN or negative time
    // was carried into every later checkpoint).
    const size_t seconds_at = good.find("seconds=") + 8, seconds_length = good.find('\n', seconds_at) - seconds_at;
    ASSERT_GE(seconds_length, 3u);
    const std::vector<Damage> forgeries = {
        {"seconds not a number", forged(seconds_at, "nan" + std::string(seconds_length - 3, ' ')), "corrupted: nan seconds of rendering"},
        {"a count past the passes", forged(count_at, std::string(reinterpret_cast<const char*>(&many), 8)), "pixel 0 is invalid: 1000 samples in 2 passes"},
        {"squares smaller than the sum allows", forged(sumsq_at, std::string(sizeof(PixelSums::sumsq[0]), '\0')), "pixel 0 is invalid: channel 0"},
    };
    for (const Damage& d : forgeries) {
        std::ofstream(path("forged.ckpt"), std::ios::binary) << d.bytes;
        const CliResult r = run({"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q", "--spp", "4", "--resume", path("forged.ckpt"), "-o",
                                 path("b.exr")});
        EXPECT_EQ(r.code, 2) << d.what << ": " << r.err;
        EXPECT_TRUE(contains(r.err, d.message)) << d.what << ": " << r.err;
        EXPECT_FALSE(fs::exists(path("b.exr")));
    }
}

// ---- merge -------------------------------------------------------------------------------

TEST_F(Distributed, MergeOfTwoHalvesEqualsTheOneShotRender) {
    const std::vector<std::string> base = {"--scene", "3", "--resolution", "16x12", "--seed", "5", "-q"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = base;
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args);
    };
    ASSERT_EQ(with({"--spp", "10", "-o", path("whole.exr"), "--checkpoint", path("whole.ckpt")}).code, 0);
    ASSERT_EQ(with({"--spp", "4", "-o", path("a.exr"), "--checkpoint", path("a.ckpt")}).code, 0);
    ASSERT_EQ(with({"--spp", "6", "--first-sample", "4", "-o", path("b.exr"), "--checkpoint", path("b.ckpt")}).code, 0);
    // From checkpoints: exact.
    CliResult m = run({"merge", path("m1.exr"), path("b.ckpt"), path("a.ckpt")});
    ASSERT_EQ(m.code, 0) << m.err;
    EXPECT_TRUE(same_render(path("m1.exr"), path("whole.exr")));
    // From the EXRs: to float precision. The merged mean is (n_a m_a + n_b m_b) / n of float
    // means (each within half an ulp of its exact value), so within 2 ulps of the one-shot mean;
    // the merged standard error comes from float standard errors and means (Chan's formula), so
    // its relative error is a few float ulps, amplified by at most |mean| / (stderr sqrt(n)).
    m = run({"merge", path("m2.exr"), path("a.exr"), path("b.exr")});
    ASSERT_EQ(m.code, 0) << m.err;
    const ExrRender got = read_render(path("m2.exr")), want = read_render(path("whole.exr"));
    EXPECT_EQ(got.attributes.at("pathlab:spp"), "10");
    EXPECT_EQ(got.attributes.at("pathlab:passes"), "0-9");
    const double ulp = std::ldexp(1.0, -23);
    size_t checked = 0;
    for (size_t i = 0; i < want.mean.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double m_want = want.mean[i][c], s_want = want.standard_error[i][c];
            EXPECT_LE(std::abs(got.mean[i][c] - m_want), 2 * ulp * std::abs(m_want)) << i;
            const double bound = 8 * ulp * (s_want + std::abs(m_want) / std::sqrt(10.0));
            EXPECT_LE(std::abs(got.standard_error[i][c] - s_want), bound) << i << " " << s_want;
            checked += s_want > 0;
        }
    EXPECT_GT(checked, 100u);
}

TEST_F(Distributed, MergeRefusesOtherScenesSizesSettingsAndRepeatedSamples) {
    const auto render = [&](std::vector<std::string> args) {
        args.insert(args.end(), {"--seed", "5", "-q", "--spp", "2"});
        ASSERT_EQ(run(args).code, 0);
    };
    render({"--scene", "3", "--resolution", "16x12", "-o", path("a.exr")});
    render({"--scene", "3", "--resolution", "16x12", "--first-sample", "2", "-o", path("b.exr")});
    render({"--scene", "4", "--resolution", "16x12", "--first-sample", "4", "-o", path("other-scene.exr")});
    render({"--scene", "3", "--resolution", "12x12", "--first-sample", "4", "-o", path("other-size.exr")});
    render({"--scene", "3", "--resolution", "16x12", "--first-sample", "4", "--max-depth", "2", "-o", path("other-depth.exr")});
    render({"--scene", "3", "--resolution", "16x12", "--first-sample", "1", "-o", path("overlap.exr")});
    struct Case {
        const char* input;
        const char* message;
    };
    for (const Case& c : {Case{"other-scene.exr", "scene hash:"}, Case{"other-size.exr", "different sizes"},
                          Case{"other-depth.exr", "options:"}, Case{"overlap.exr", "both hold passes of seed 5"}}) {
        const CliResult r = run({"merge", path("m.exr"), path("a.exr"), path(c.input)});
        EXPECT_EQ(r.code, 2) << c.input << ": " << r.err;
        EXPECT_TRUE(contains(r.err, c.message)) << c.input << ": " << r.err;
        EXPECT_FALSE(fs::exists(path("m.exr")));
    }
    // Not a render of pathlab's: no attributes.
    write_image(read_image(path("a.exr")), path("plain.exr"));
    const CliResult plain = run({"merge", path("m.exr"), path("a.exr"), path("plain.exr")});
    EXPECT_EQ(plain.code, 2);
    EXPECT_TRUE(contains(plain.err, "not a pathlab render")) << plain.err;
    // A merged image merges on: other seeds too.
    ASSERT_EQ(run({"merge", path("ab.exr"), path("a.exr"), path("b.exr")}).code, 0);
    ASSERT_EQ(run({"--scene", "3", "--resolution", "16x12", "--seed", "9", "-q", "--spp", "2", "-o", path("c.exr")}).code, 0);
    const CliResult again = run({"merge", path("abc.exr"), path("ab.exr"), path("c.exr")});
    ASSERT_EQ(again.code, 0) << again.err;
    EXPECT_EQ(read_render(path("abc.exr")).attributes.at("pathlab:parts"), "5:0-3;9:0-1");
    EXPECT_EQ(run({"merge", path("m.exr"), path("abc.exr"), path("a.exr")}).code, 2);
}

// ---- processes: the plain binary, mpirun, kill -9 ------------------------------------------

TEST_F(Distributed, PlainBinaryRunsWithoutMpirunAndForcedSingletonMpiToo) {
    const std::string cmd = fmt::format("{} {} --spp 3 -o {}", PATHLAB_BINARY, kSmall, path("plain.exr"));
    ASSERT_EQ(shell(cmd), 0);
    std::string err;
    ASSERT_EQ(shell(fmt::format("PATHLAB_MPI=1 timeout 60 {} {} --spp 3 -o {}", PATHLAB_BINARY, kSmall, path("singleton.exr")), &err), 0) << err;
    EXPECT_TRUE(same_render(path("plain.exr"), path("singleton.exr")));
}

// One scene file per integrator (the course's scene 3 with its <integrator>; volpath: scene 2
// in fog, whose file names volpath), all rendered by one command: one mpirun start instead of
// one per integrator, with `flags` added. pbgi with a small cloud: its surfels and corner gathers
// are made by every rank alike.
void Distributed::expect_two_ranks_equal_one_process(const std::vector<std::string>& algorithms, const std::string& flags) {
    if (!fs::exists(dir_ / "meshes")) fs::create_directory_symlink(fs::path(PATHLAB_SOURCE_DIR) / "scenes/meshes", dir_ / "meshes");
    const std::string scene = file_bytes(std::string(PATHLAB_SOURCE_DIR) + "/scenes/3-ceiling-glossy.xml");
    const std::string open = "<scene version=\"3.0.0\">";
    ASSERT_NE(scene.find(open), std::string::npos);
    std::string list;
    const std::string fog = file_bytes(std::string(PATHLAB_SOURCE_DIR) + "/scenes/fog-ceiling.xml");
    ASSERT_NE(fog.find("<integrator type=\"volpath\"/>"), std::string::npos);
    for (const std::string& a : algorithms) {
        std::string text = a == "volpath" ? fog : scene;
        if (a != "volpath")
            text.insert(text.find(open) + open.size(),
                        a == "pbgi"  ? "<integrator type=\"pbgi\"><integer name=\"surfels\" value=\"1500\"/></integrator>"
                        : a == "ppg" ? "<integrator type=\"ppg\"><string name=\"guiding_fraction\" value=\"learned\"/><boolean "
                                       "name=\"guiding_rr\" value=\"true\"/></integrator>"
                                     : "<integrator type=\"" + a + "\"/>");
        std::ofstream(path(a + ".xml")) << text;
        list += (list.empty() ? "" : ",") + path(a + ".xml");
    }
    const std::string args = fmt::format("--scene {} --resolution 16x12 --seed 5 -q --spp 5 {}", list, flags);
    std::string err;
    ASSERT_EQ(shell(fmt::format("{} {} --threads 2 -o {}", PATHLAB_BINARY, args, path("one-{scene}.exr")), &err), 0) << err;
    ASSERT_EQ(shell(fmt::format("{} {} --threads 1 -o {}", mpirun(2), args, path("two-{scene}.exr")), &err), 0) << err;
    for (const std::string& a : algorithms) {
        EXPECT_EQ(read_render(path("one-" + a + ".exr")).attributes.at("pathlab:integrator"), a);
        EXPECT_TRUE(same_render(path("one-" + a + ".exr"), path("two-" + a + ".exr"))) << a << " " << flags;
    }
}

// ppg's ranks train one tree together (each traces a share of the rows, the records exchanged and
// added in row order), here with the learned fraction and the adjoint-driven roulette.
TEST_F(Distributed, TwoRanksOfOneThreadEqualOneProcessOfTwoThreadsForEveryIntegrator) {
    expect_two_ranks_equal_one_process({"pt-mis", "lt", "bdpt", "sppm", "ppm", "pm", "vcm", "bpm", "ic", "pbgi", "volpath", "pssmlt", "ppg"}, "");
    expect_two_ranks_equal_one_process({"mmlt"}, "--max-depth 5");
}

// Spectral mode's wavelengths come from per-sample (or per-pass) streams, so ranks give the
// one-process bytes there too.
TEST_F(Distributed, TwoRanksEqualOneProcessInSpectralMode) {
    expect_two_ranks_equal_one_process({"pt-mis", "lt", "bdpt", "sppm", "pm", "vcm", "ic", "pbgi", "volpath", "ppg"}, "--spectral");
}

// --display-server with two ranks: the root sends the ranks' films summed. The first update
// after the first round (passes 0 and 1, one per rank) equals a one-process render of 2 spp, and
// the last equals the image written.
TEST_F(Distributed, TwoRanksStreamTheSummedFilmToTheViewer) {
    FakeTev tev;
    std::string err;
    ASSERT_EQ(shell(fmt::format("{} {} -a lt --spp 40 --threads 1 --display-server {} -o {}", mpirun(2), kSmall, tev.address(),
                                path("two.pfm")), &err), 0)
        << err;
    ASSERT_EQ(shell(fmt::format("{} {} -a lt --spp 2 --threads 1 -o {}", PATHLAB_BINARY, kSmall, path("first.pfm")), &err), 0) << err;
    const std::vector<std::string> got = wait_for(tev, 1);
    ASSERT_EQ(got.size(), 1u) << "one connection, from the root";
    const std::vector<TevPacket> ps = parse_packets(got[0]);
    ASSERT_GE(ps.size(), 3u);
    EXPECT_EQ(ps[0].type, 4);
    const auto equal = [](const TevPacket& p, const Image& image) {
        if (p.type != 6 || size_t(p.width) * size_t(p.height) != image.pixel_count()) return false;
        for (size_t i = 0; i < image.pixel_count(); ++i)
            for (int c = 0; c < 3; ++c)
                if (p.data[size_t(c)][i] != image[i][c]) return false;
        return true;
    };
    EXPECT_TRUE(equal(ps[1], read_image(path("first.pfm"))));
    EXPECT_TRUE(equal(ps.back(), read_image(path("two.pfm"))));
}

TEST_F(Distributed, RanksWithATimeBudgetAgreeOnOneSampleCount) {
    std::string err;
    ASSERT_EQ(shell(fmt::format("{} {} --time 0.5 --threads 1 --stats {} -o {}", mpirun(2), kSmall, path("s.json"), path("two.exr")), &err), 0)
        << err;
    const ExrRender r = read_render(path("two.exr"));
    const std::string spp = r.attributes.at("pathlab:spp");
    EXPECT_EQ(r.attributes.at("pathlab:passes"), "0-" + std::to_string(std::stoull(spp) - 1));
    const std::string stats = file_bytes(path("s.json"));
    EXPECT_TRUE(contains(stats, "\"ranks\"")) << stats;
    ASSERT_EQ(shell(fmt::format("{} {} --spp {} -o {}", PATHLAB_BINARY, kSmall, spp, path("one.exr"))), 0);
    EXPECT_TRUE(same_render(path("one.exr"), path("two.exr")));
}

TEST_F(Distributed, CheckpointOfTwoRanksResumesInOneProcess) {
    std::string err;
    ASSERT_EQ(shell(fmt::format("{} {} -a lt --spp 5 --threads 1 --checkpoint {} -o {}", mpirun(2), kSmall, path("c.ckpt"), path("part.exr")),
                    &err),
              0)
        << err;
    ASSERT_EQ(shell(fmt::format("{} {} -a lt --spp 11 --resume {} -o {}", PATHLAB_BINARY, kSmall, path("c.ckpt"), path("resumed.exr"))), 0);
    ASSERT_EQ(shell(fmt::format("{} {} -a lt --spp 11 -o {}", PATHLAB_BINARY, kSmall, path("whole.exr"))), 0);
    EXPECT_TRUE(same_render(path("whole.exr"), path("resumed.exr")));
    // A scene file a rank cannot read: every rank stops with the error, none waits for ever.
    const int code = shell(fmt::format("{} --scene {} -q --spp 2 -o {}", mpirun(2), path("missing.xml"), path("x.exr")), &err);
    EXPECT_EQ(code, 2) << err;
    EXPECT_TRUE(contains(err, "missing.xml")) << err;
}

// kill -9 after the first checkpoint, then --resume: the image of the uninterrupted render.
TEST_F(Distributed, RenderKilledAfterItsFirstCheckpointResumesToTheUninterruptedImage) {
    const std::string args = "--scene 3 --resolution 24x24 --seed 5 -q --threads 1 --spp 400";
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        const std::string cmd = fmt::format("exec {} {} --checkpoint {} --checkpoint-every 0.05 -o {}", PATHLAB_BINARY, args, path("c.ckpt"),
                                            path("killed.exr"));
        execl("/bin/sh", "sh", "-c", cmd.c_str(), nullptr);
        _exit(127);
    }
    const auto start = std::chrono::steady_clock::now();
    while (!fs::exists(path("c.ckpt")) && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "the render ended before it was killed: make it longer";
    EXPECT_FALSE(fs::exists(path("killed.exr")));
    const CheckpointInfo info = read_checkpoint_info(path("c.ckpt"));
    EXPECT_GT(info.passes.count(), 0u);
    EXPECT_LT(info.passes.count(), 400u);
    std::string err;
    ASSERT_EQ(shell(fmt::format("{} {} --resume {} -o {}", PATHLAB_BINARY, args, path("c.ckpt"), path("resumed.exr")), &err), 0) << err;
    ASSERT_EQ(shell(fmt::format("{} {} -o {}", PATHLAB_BINARY, args, path("whole.exr"))), 0);
    EXPECT_TRUE(same_render(path("whole.exr"), path("resumed.exr")));
}

// SIGTERM (a scheduler's time limit): the image so far and a checkpoint, then resumed.
TEST_F(Distributed, TerminatedRenderWritesItsImageAndCheckpointAndResumes) {
    const std::string args = "--scene 3 --resolution 24x24 --seed 5 -q --threads 1 --spp 400";
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        const std::string cmd = fmt::format("exec {} {} --checkpoint {} --checkpoint-every 0.05 -o {}", PATHLAB_BINARY, args, path("c.ckpt"),
                                            path("stopped.exr"));
        execl("/bin/sh", "sh", "-c", cmd.c_str(), nullptr);
        _exit(127);
    }
    // Once it has checkpointed, it is rendering (and handles the signal).
    const auto start = std::chrono::steady_clock::now();
    while (!fs::exists(path("c.ckpt")) && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 143);
    const ExrRender stopped = read_render(path("stopped.exr"));
    const CheckpointInfo info = read_checkpoint_info(path("c.ckpt"));
    EXPECT_EQ(stopped.attributes.at("pathlab:passes"), info.passes.to_string());
    EXPECT_LT(info.passes.count(), 400u);
    ASSERT_EQ(shell(fmt::format("{} {} --resume {} -o {}", PATHLAB_BINARY, args, path("c.ckpt"), path("resumed.exr"))), 0);
    ASSERT_EQ(shell(fmt::format("{} {} -o {}", PATHLAB_BINARY, args, path("whole.exr"))), 0);
    EXPECT_TRUE(same_render(path("whole.exr"), path("resumed.exr")));
}

}  // namespace
}  // namespace pathlab::test
