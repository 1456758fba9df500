// Bidirectional path tracing: bdpt converges to pt-mis's image (z-tests on the course scenes,
// on scene files with glass, mirrors, rough and plastic materials, and on the shipped caustic
// and lampshade scenes) and fails for a MIS weight that drops a strategy or a reverse density
// left unset at a mirror; per path length, every strategy converges to that length's image and
// the weighted ones add up to it; images are bit-identical for any thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>
#include <filesystem>
#include <unistd.h>

#include <fmt/format.h>

#include "integrators/bidir/bdpt.hpp"
#include "integrators/bidir/strategy_images.hpp"
#include "image/image_io.hpp"
#include "integrators/integrators.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

// Each comparison raises a false alarm with probability <= 1e-4 (image_statistics.hpp).
const AgreementOptions kAgreement{1e-3, 1e-4};
constexpr uint64_t kSpp = 32768;

SceneDescription scene_of(const std::string& key) {
    // The caustic with a larger light of the same power: with the shipped small light, the
    // caustic's paths are found too rarely per pixel at test sample counts for the z-test's
    // normal approximation to hold (a few hits of a bright light per pixel).
    if (key == "caustic.xml")
        return load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/caustic.xml", {{"light_size", "0.36"}, {"light_radiance", "33.3"}});
    // Scene files: the tests' own, or those shipped in scenes/.
    const std::string tests_dir = std::string(PATHLAB_SOURCE_DIR) + "/tests/data/scenes/";
    if (looks_like_scene_file(key))
        return load_scene_file(std::filesystem::exists(tests_dir + key) ? tests_dir + key : std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + key);
    return make_builtin_scene(std::stoi(key));
}

AgreementResult agreement(const Film& a, const Film& b) {
    return test_agreement(a.mean(), a.standard_error(), b.mean(), b.standard_error(), kAgreement);
}

// pt-mis's image of the scene, with the same options (depth, or one path length only).
RenderResult pt_mis_render(const SceneDescription& d, const IntegratorOptions& o, int w, int h, uint64_t spp, uint64_t seed) {
    const std::unique_ptr<Integrator> pt = find_integrator("pt-mis")->make(o);
    return render_integrator(d, *pt, w, h, spp, seed);
}

AgreementResult compare_with_pt_mis(const std::string& key, Integrator& bdpt, int w, int h, uint64_t spp) {
    const SceneDescription d = scene_of(key);
    return agreement(render_integrator(d, bdpt, w, h, spp, 401).film, pt_mis_render(d, {}, w, h, spp, 402).film);
}

class BdptAgreement : public ::testing::TestWithParam<std::string> {};

TEST_P(BdptAgreement, ConvergesToThePathTracersImage) {
    Bdpt<RgbTransport> bdpt({});
    const bool file = looks_like_scene_file(GetParam());
    // The shipped scenes (caustic, lampshade) are slow to converge for pt-mis: fewer pixels.
    const bool shipped = GetParam() == "caustic.xml" || GetParam() == "lampshade.xml";
    const AgreementResult r = shipped ? compare_with_pt_mis(GetParam(), bdpt, 8, 6, 16384)
                              : file  ? compare_with_pt_mis(GetParam(), bdpt, 16, 12, 16384)
                                      : compare_with_pt_mis(GetParam(), bdpt, 8, 8, kSpp);
    ::testing::Test::RecordProperty("agreement", r.describe());
    EXPECT_TRUE(r.agree) << GetParam() << ": " << r.describe();
}
INSTANTIATE_TEST_SUITE_P(Scenes, BdptAgreement,
                         ::testing::Values("0", "1", "2", "3", "4", "5", "6", "7", "specular-box.xml", "specular-sky.xml", "mirror-box.xml", "caustic.xml",
                                           "lampshade.xml"),
                         [](const auto& info) {
                             std::string n = info.param;
                             for (char& c : n) if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return "scene_" + n;
                         });


// The tests of the tests: the same comparison fails for weights that leave next-event
// estimation out of their sums (too bright where it could sample), and for a reverse density
// left unset at a mirror vertex (the weights of the strategies on either side of it no longer
// sum to 1; mirror-box.xml is made so that they carry comparable weights).
TEST(BdptAgreement, DetectsAMisWeightThatDropsAStrategy) {
    Bdpt<RgbTransport> bdpt({}, BdptFaults{.drop_nee_strategy = true});
    const AgreementResult r = compare_with_pt_mis("2", bdpt, 8, 8, 4096);
    EXPECT_FALSE(r.agree) << r.describe();
}

TEST(BdptAgreement, DetectsAMissingReversePdfAtASpecularVertex) {
    Bdpt<RgbTransport> bdpt({}, BdptFaults{.specular_pdf_rev_missing = true});
    const AgreementResult r = compare_with_pt_mis("mirror-box.xml", bdpt, 16, 12, 16384);
    EXPECT_FALSE(r.agree) << r.describe();
}

TEST(BdptDeterminism, OneAndTwoThreadsGiveBitIdenticalImages) {
    for (const char* key : {"5", "specular-sky.xml"}) {
        RenderResult runs[2];
        for (const int threads : {1, 2}) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
            Bdpt<RgbTransport> bdpt({});
            runs[threads - 1] = render_integrator(scene_of(key), bdpt, 40, 30, 4, 9);
        }
        EXPECT_TRUE(bit_identical(runs[0].film.mean(), runs[1].film.mean())) << key;
        EXPECT_TRUE(bit_identical(runs[0].film.standard_error(), runs[1].film.standard_error())) << key;
        EXPECT_EQ(runs[0].stats.rays, runs[1].stats.rays) << key;
    }
}

// Per path length: the weighted strategies add up to bdpt's own image of the length (to
// rounding: a restricted render is made of the same paths, see bdpt.cpp), which agrees with
// pt-mis restricted to that length; the files and montages are written. On strategies.xml,
// where each strategy has a finite variance (see the file), each unweighted strategy is an
// estimator of the length's image by itself and agrees with pt-mis's too. (In the Cornell
// boxes the unweighted strategies have infinite variance, and a z-test does not apply.)
struct StrategiesCase {
    std::string scene;
    bool unweighted_z_tests;
};

void PrintTo(const StrategiesCase& c, std::ostream* os) { *os << c.scene; }

class BdptStrategies : public ::testing::TestWithParam<StrategiesCase> {};

TEST_P(BdptStrategies, EachLengthsStrategiesAddUpAndConverge) {
    constexpr int kDepth = 2, kW = 8, kH = 6;
    constexpr uint64_t kStrategySpp = 16384;
    const SceneDescription d = scene_of(GetParam().scene);
    const std::string dir = ::testing::TempDir() + "bdpt-strategies-" + std::to_string(::getpid());
    std::filesystem::create_directories(dir);
    IntegratorOptions o;
    o.max_depth = kDepth;
    o.strategies_dir = dir;
    o.strategies_depth = kDepth;
    Bdpt<RgbTransport> bdpt(o);
    render_integrator(d, bdpt, kW, kH, kStrategySpp, 5);  // fills the strategies' films and writes them
    const StrategyImages& images = *bdpt.strategy_images();
    for (int n = 0; n <= kDepth; ++n) {
        IntegratorOptions length = o;
        length.only_length = n;
        length.strategies_dir.clear();
        const RenderResult reference = pt_mis_render(d, length, kW, kH, kStrategySpp, 77 + uint64_t(n));
        Bdpt<RgbTransport> bdpt_n(length);
        const RenderResult own = render_integrator(d, bdpt_n, kW, kH, kStrategySpp, 5);
        const AgreementResult weighted = agreement(own.film, reference.film);
        EXPECT_TRUE(weighted.agree) << "length " << n << ", bdpt: " << weighted.describe();
        Image sum(kW, kH);
        for (int s = 0; s <= n + 1; ++s) {
            const int t = n + 2 - s;
            if (s == 1 && t == 1) continue;
            if (GetParam().unweighted_z_tests) {
                const AgreementResult r = agreement(images.unweighted(s, t), reference.film);
                EXPECT_TRUE(r.agree) << "length " << n << ", unweighted s=" << s << " t=" << t << ": " << r.describe();
            }
            const Image w = images.weighted(s, t).mean();
            for (size_t i = 0; i < sum.pixel_count(); ++i) sum[i] += w[i];
            EXPECT_TRUE(std::filesystem::exists(fmt::format("{}/n{}-s{}-t{}-weighted.exr", dir, n, s, t)));
            EXPECT_TRUE(std::filesystem::exists(fmt::format("{}/n{}-s{}-t{}-unweighted.exr", dir, n, s, t)));
        }
        const Image mine = own.film.mean();
        for (size_t i = 0; i < sum.pixel_count(); ++i)
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(sum[i][c], mine[i][c], 1e-5f * std::max(1.0f, mine[i][c])) << "length " << n << ", pixel " << i;
    }
    // The montages: labels in their top and left margins (white text on black), and each row
    // (path length) at an exposure of its own, so that every row shows its light (one exposure
    // for all left the longer paths black).
    for (const char* name : {"/montage-weighted.png", "/montage-unweighted.png"}) {
        const Image8 m = read_png8(dir + name);
        const int cols = kDepth + 2, gap = 2, top = 14, left = m.width - (cols * (kW + gap) - gap);
        ASSERT_EQ(m.height, top + (kDepth + 1) * (kH + gap) - gap) << name;
        ASSERT_GT(left, 20) << name << ": room for the row labels";
        const auto white = [&](int x0, int x1, int y0, int y1) {
            int n = 0;
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) n += m.at(x, y, 0) == 255 && m.at(x, y, 1) == 255 && m.at(x, y, 2) == 255;
            return n;
        };
        EXPECT_GT(white(left, m.width, 0, top), 20) << name << ": the s labels";
        int rows_lit = 0;
        for (int n = 0; n <= kDepth; ++n) {
            const int y0 = top + n * (kH + gap);
            EXPECT_GT(white(0, left, y0, y0 + kH), 10) << name << ": the label of row " << n;
            std::vector<double> lit;  // the row's lit pixels' luminance, as the montage scales them
            for (int s = 0; s <= n + 1; ++s) {
                if (s == 1 && n == 0) continue;
                for (int y = y0; y < y0 + kH; ++y)
                    for (int x = left + s * (kW + gap); x < left + s * (kW + gap) + kW; ++x)
                        if (const double l = 0.2126 * m.at(x, y, 0) + 0.7152 * m.at(x, y, 1) + 0.0722 * m.at(x, y, 2); l > 0) lit.push_back(l);
            }
            if (lit.empty()) continue;  // no light of this length here (strategies.xml's light is not seen directly)
            ++rows_lit;
            std::nth_element(lit.begin(), lit.begin() + lit.size() / 2, lit.end());
            // 0.18 in sRGB is 118 of 255; the rounding of 8 bits and the cells' colours move it.
            EXPECT_GT(lit[lit.size() / 2], 80) << name << ": row " << n << " is too dark to read";
            EXPECT_LT(lit[lit.size() / 2], 160) << name << ": row " << n;
        }
        EXPECT_GE(rows_lit, kDepth) << name;
    }
    std::filesystem::remove_all(dir);
}
INSTANTIATE_TEST_SUITE_P(Scenes, BdptStrategies,
                         ::testing::Values(StrategiesCase{"strategies.xml", true}, StrategiesCase{"3", false},
                                           StrategiesCase{"5", false}),
                         [](const auto& info) { return info.index == 0 ? std::string("strategies_xml") : "scene_" + info.param.scene; });

}  // namespace
}  // namespace pathlab::test
