// Participating media (src/media): the phase functions' and free-flight sampling's densities by
// chi-square, transmittance by delta tracking, ratio tracking and the closed form, the voxel
// grid's interpolation, and the .vol and .vdb readers (round trips, placement, bad files).
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "chi2.hpp"
#include "media/grid_files.hpp"
#include "media/medium.hpp"

namespace pathlab::test {
namespace {
namespace fs = std::filesystem;

// ---- phase functions ------------------------------------------------------------------------

const Vec3f kWi = normalize(Vec3f(0.3f, -0.4f, 0.8f));

// Chi-square of a phase function's sampling against `pdf` (its own pdf by default).
Chi2Result phase_chi2(const PhaseFunction& f, const std::function<float(const Vec3f&)>& pdf = {}) {
    Chi2Options o;
    o.samples = 400'000;
    o.theta_power = 2;  // narrow lobes (|g| = 0.9) sit at the pole
    const float g = std::holds_alternative<HgPhase>(f) ? std::get<HgPhase>(f).g : 0.0f;
    // The lobe's peak at the histogram's pole: forward (-wi) or backward (wi).
    const Vec3f axis = g >= 0 ? -kWi : kWi;
    return chi2_directions([&](Vec2f u) -> std::optional<Vec3f> { return phase_sample(f, kWi, u).wo; },
                           pdf ? pdf : [&](const Vec3f& wo) { return phase_pdf(f, kWi, wo); }, axis, o);
}

// The verdict of the two checks below: the samples fit the pdf, and the pdf integrates to 1.
bool fits(const Chi2Result& r) { return r.p_value > suite_chi2_alpha() && std::abs(r.pdf_integral - 1) < 2e-3; }

TEST(Phase, HenyeyGreensteinSamplingMatchesItsPdf) {
    for (float g : {-0.9f, -0.5f, -0.1f, 0.0f, 0.3f, 0.7f, 0.9f}) {
        const Chi2Result r = phase_chi2(HgPhase{g});
        EXPECT_GT(r.p_value, suite_chi2_alpha()) << "g = " << g << ": " << r.describe();
        EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << "g = " << g;
    }
    const Chi2Result iso = phase_chi2(IsotropicPhase{});
    EXPECT_GT(iso.p_value, suite_chi2_alpha()) << iso.describe();
    EXPECT_NEAR(iso.pdf_integral, 1.0, 2e-3);
}

// The test of the test: a pdf 2% off is rejected, whether all of it is 2% too large (the
// integral says so) or its g is 2% off (the chi-square statistic says so).
TEST(Phase, APdfTwoPercentOffIsRejected) {
    for (float g : {-0.9f, 0.7f}) {
        const HgPhase hg{g}, wrong{g * 1.02f};
        const Chi2Result scaled = phase_chi2(hg, [&](const Vec3f& wo) { return 1.02f * hg.pdf(kWi, wo); });
        EXPECT_FALSE(fits(scaled)) << "g = " << g << ": " << scaled.describe();
        const Chi2Result shape = phase_chi2(hg, [&](const Vec3f& wo) { return wrong.pdf(kWi, wo); });
        EXPECT_FALSE(fits(shape)) << "g = " << g << ": " << shape.describe();
    }
}

TEST(Phase, SampleReportsItsValueAndDensityAndHgMeanCosineIsG) {
    for (float g : {-0.7f, 0.0f, 0.5f}) {
        const HgPhase hg{g};
        double mean_cos = 0;
        const int n = 200'000;
        Sampler s(3, 0, 0);
        for (int i = 0; i < n; ++i) {
            const PhaseSample ps = hg.sample(kWi, s.next2d());
            EXPECT_FLOAT_EQ(ps.p, hg.eval(kWi, ps.wo));
            EXPECT_FLOAT_EQ(ps.pdfW, hg.pdf(kWi, ps.wo));
            mean_cos += dot(-kWi, ps.wo);
        }
        // The mean cosine of HG is g; its variance is at most 1, so 5 standard errors is < 0.012.
        EXPECT_NEAR(mean_cos / n, g, 0.012) << "g = " << g;
    }
}

// ---- free-flight sampling -------------------------------------------------------------------

// A smooth, positive 3-channel grid (3 x 4 x 5 voxels, different per channel).
VoxelGrid test_grid() {
    VoxelGrid g;
    g.res = {5, 4, 3};
    g.channels = 3;
    for (int z = 0; z < g.res[2]; ++z)
        for (int y = 0; y < g.res[1]; ++y)
            for (int x = 0; x < g.res[0]; ++x)
                for (int c = 0; c < 3; ++c)
                    g.data.push_back(0.2f + 0.5f * float((x * 7 + y * 3 + z * 5 + c * 2) % 6) + (c == 1 ? 0.3f : 0.0f));
    return g;
}

// A heterogeneous medium filling the box [-1, 1] x [-1, 1] x [-0.5, 0.5] with the test grid.
HeterogeneousMedium test_grid_medium(float scale = 1.5f) {
    HeterogeneousMedium m;
    m.sigma_t = Volume::of_grid(test_grid(), Transform::translate({-1, -1, -0.5}) * Transform::scale({2, 2, 1}));
    m.albedo = Volume::constant_value(Rgb(0.8f, 0.6f, 0.9f));
    m.scale = scale;
    m.prepare();
    return m;
}

// The optical depth of channel c along o + t d up to t, by the midpoint rule on a fine grid
// (the interpolated extinction is continuous and piecewise smooth).
double optical_depth(const Medium& m, const Vec3f& o, const Vec3f& d, double t, int c, int steps = 20000) {
    double tau = 0;
    for (int i = 0; i < steps; ++i) {
        const double s = (i + 0.5) * t / steps;
        tau += medium_coefficients(m, o + d * float(s)).sigma_t[c];
    }
    return tau * t / steps;
}

// Chi-square of the distance at which free-flight sampling scatters (bins of [0, tmax) and one
// cell for passing tmax) against the exact distribution, 1 - exp(-optical depth).
Chi2Result free_flight_chi2(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, int hero, float majorant_factor,
                            int samples = 200'000) {
    constexpr int kBins = 40;
    std::vector<double> observed(kBins + 1, 0.0), expected(kBins + 1, 0.0);
    for (int i = 0; i < samples; ++i) {
        Sampler rng(11, uint64_t(hero), uint64_t(i));
        Rgb beta(1.0f), r(1.0f);
        const FreeFlight ff = sample_free_flight(m, o, d, tmax, hero, rng, beta, r, majorant_factor);
        if (ff.scattered) observed[size_t(std::min(kBins - 1, int(ff.t / tmax * kBins)))] += 1;
        else observed[kBins] += 1;
    }
    double previous = 1;  // exp(-tau(0))
    for (int b = 0; b < kBins; ++b) {
        const double next = std::exp(-optical_depth(m, o, d, double(tmax) * (b + 1) / kBins, hero, 2000));
        expected[size_t(b)] = samples * (previous - next);
        previous = next;
    }
    expected[kBins] = samples * previous;
    return chi2_from_counts(observed, expected);
}

TEST(FreeFlight, HomogeneousDistancesFollowEachHeroChannelsExponential) {
    const Medium m = HomogeneousMedium{Rgb(0.5f, 1.5f, 3.0f), Rgb(0.4f, 1.0f, 2.0f), IsotropicPhase{}};
    const Vec3f o(0.1f, 0.2f, 0.3f), d = normalize(Vec3f(1, 2, -1));
    for (int hero = 0; hero < 3; ++hero) {
        const Chi2Result r = free_flight_chi2(m, o, d, 1.2f, hero, 1);
        EXPECT_GT(r.p_value, suite_chi2_alpha()) << "hero " << hero << ": " << r.describe();
        // ... and the sampling density is what free_flight_pdf says (the bins integrate it).
        const auto& h = std::get<HomogeneousMedium>(m);
        EXPECT_NEAR(free_flight_pdf(h, 0.7f, hero), h.sigma_t[hero] * std::exp(-h.sigma_t[hero] * 0.7f), 1e-6f);
    }
    // Null collisions (a majorant twice the largest extinction) thin to the same distribution.
    const Chi2Result thinned = free_flight_chi2(m, o, d, 1.2f, 1, 2);
    EXPECT_GT(thinned.p_value, suite_chi2_alpha()) << thinned.describe();
}

TEST(FreeFlight, DeltaTrackingInAGridFollowsTheExactDistribution) {
    const Medium m = test_grid_medium();
    // A ray crossing the grid obliquely, starting outside it and ending beyond it.
    const Vec3f o(-1.5f, -0.8f, -0.7f), d = normalize(Vec3f(2.4f, 1.3f, 1.0f));
    for (int hero = 0; hero < 3; ++hero) {
        const Chi2Result r = free_flight_chi2(m, o, d, 3.5f, hero, 1);
        EXPECT_GT(r.p_value, suite_chi2_alpha()) << "hero " << hero << ": " << r.describe();
    }
}

TEST(FreeFlight, GreyMediaKeepTheChannelRatiosAtExactlyOne) {
    const Medium grey = HomogeneousMedium{Rgb(0.7f), Rgb(0.5f), IsotropicPhase{}};
    Sampler rng(5, 0, 0);
    for (int i = 0; i < 1000; ++i) {
        Rgb beta(1.0f), r(1.0f);
        const FreeFlight ff = sample_free_flight(grey, Vec3f(0.0f), Vec3f(0, 0, 1), 2.0f, i % 3, rng, beta, r);
        EXPECT_EQ(r, Rgb(1.0f));
        EXPECT_EQ(beta.x, beta.y);
        if (ff.scattered) {
            EXPECT_FLOAT_EQ(beta.x, 0.5f / 0.7f);
        } else {
            EXPECT_EQ(beta, Rgb(1.0f));
        }
    }
}

// ---- transmittance --------------------------------------------------------------------------

struct Estimate {
    double mean = 0, se = 0;
};
template <typename F>
Estimate estimate(int n, F&& sample) {
    double s = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
        const double x = sample(i);
        s += x, s2 += x * x;
    }
    const double mean = s / n;
    return {mean, std::sqrt(std::max(0.0, s2 / n - mean * mean) / (n - 1))};
}

// |z| below 4.4: a false alarm with probability 1e-5 per comparison.
constexpr double kZ = 4.4;

// Delta tracking's "no real collision before d" with hero channel c, as an estimate of T_c.
Estimate delta_tracking(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, int c, float factor, int n) {
    return estimate(n, [&](int i) {
        Sampler rng(21, uint64_t(c), uint64_t(i));
        Rgb beta(1.0f), r(1.0f);
        return sample_free_flight(m, o, d, tmax, c, rng, beta, r, factor).scattered ? 0.0 : 1.0;
    });
}
Estimate ratio_tracking(const Medium& m, const Vec3f& o, const Vec3f& d, float tmax, int c, float factor, int n) {
    return estimate(n, [&](int i) {
        Sampler rng(22, uint64_t(c), uint64_t(i));
        return double(estimate_transmittance(m, o, d, tmax, rng, factor)[c]);
    });
}

TEST(Transmittance, HomogeneousDeltaRatioAndClosedFormAgree) {
    const HomogeneousMedium h{Rgb(0.5f, 1.0f, 2.0f), Rgb(0.3f), IsotropicPhase{}};
    const Medium m = h;
    const Vec3f o(0.2f, 0.1f, 0.0f), d = normalize(Vec3f(0.3f, -1, 0.2f));
    const float dist = 1.3f;
    Sampler unused(0, 0, 0);
    const Rgb exact = estimate_transmittance(m, o, d, dist, unused);  // the closed form
    for (int c = 0; c < 3; ++c) {
        const double T = std::exp(-double(h.sigma_t[c]) * dist);
        EXPECT_NEAR(exact[c], T, 1e-6);
        for (float factor : {1.0f, 2.5f}) {  // exact sampling, and null collisions
            const Estimate delta = delta_tracking(m, o, d, dist, c, factor, 100'000);
            EXPECT_LT(std::abs(delta.mean - T), kZ * std::sqrt(T * (1 - T) / 100'000)) << "channel " << c << ", factor " << factor;
        }
        const Estimate ratio = ratio_tracking(m, o, d, dist, c, 2.5f, 100'000);
        EXPECT_LT(std::abs(ratio.mean - T), kZ * ratio.se) << "channel " << c << ": " << ratio.mean << " +- " << ratio.se;
    }
}

TEST(Transmittance, RatioAndDeltaTrackingAgreeInAGrid) {
    const Medium m = test_grid_medium(0.4f);
    const Vec3f o(-1.2f, 0.9f, -0.3f), d = normalize(Vec3f(2.0f, -1.5f, 0.4f));
    const float dist = 2.6f;
    for (int c = 0; c < 3; ++c) {
        const Estimate delta = delta_tracking(m, o, d, dist, c, 1, 100'000);
        const Estimate ratio = ratio_tracking(m, o, d, dist, c, 1, 100'000);
        const double T = std::exp(-optical_depth(m, o, d, dist, c));
        EXPECT_GT(T, 0.02);
        EXPECT_LT(T, 0.98);
        const double se = std::sqrt(delta.se * delta.se + ratio.se * ratio.se);
        EXPECT_LT(std::abs(delta.mean - ratio.mean), kZ * se) << "channel " << c << ": delta " << delta.mean << ", ratio " << ratio.mean;
        // Both against the optical depth integrated along the ray.
        EXPECT_LT(std::abs(ratio.mean - T), kZ * ratio.se) << "channel " << c;
        EXPECT_LT(std::abs(delta.mean - T), kZ * delta.se) << "channel " << c;
    }
}

// A connection's transmittance and its MIS transmittance in one walk give what the two
// functions give apart, bit for bit (the same random numbers; the same midpoint sums), in a
// grid and in a homogeneous medium, from inside, from outside and through a majorant factor.
TEST(Transmittance, WithMisEqualsTheTwoFunctionsBitForBit) {
    const Medium grid = test_grid_medium(0.4f), fog = HomogeneousMedium{Rgb(0.5f, 1.0f, 2.0f), Rgb(0.3f), IsotropicPhase{}};
    Sampler s(31, 0, 0);
    int differing = 0, compared = 0;
    for (const Medium* m : {&grid, &fog})
        for (int i = 0; i < 2000; ++i) {
            const Vec3f o(s.next1d() * 3 - 1.5f, s.next1d() * 3 - 1.5f, s.next1d() * 2 - 1);
            const Vec3f d = normalize(Vec3f(s.next1d() - 0.5f, s.next1d() - 0.5f, s.next1d() - 0.5f));
            const float tmax = s.next1d() * 3, factor = i % 3 == 0 ? 1.7f : 1.0f;
            Sampler a(5, 1, uint64_t(i)), b(5, 1, uint64_t(i));
            float mis = -1;
            const Rgb together = estimate_transmittance_with_mis(*m, MediumRgb{*m}, o, d, tmax, a, factor, mis);
            const Rgb apart = estimate_transmittance(*m, o, d, tmax, b, factor);
            const float expected = mis_transmittance(*m, o, d, tmax);
            ++compared;
            if (std::memcmp(&together, &apart, sizeof(Rgb)) != 0 || (!is_black(together) && std::memcmp(&mis, &expected, sizeof mis) != 0))
                ++differing;
        }
    EXPECT_EQ(differing, 0) << "of " << compared;
}

TEST(Transmittance, MajorantsBoundEveryLookup) {
    const HeterogeneousMedium g = test_grid_medium();
    const Medium m = g;
    Sampler s(9, 0, 0);
    for (int i = 0; i < 20000; ++i) {
        const Vec3f o(s.next1d() * 3 - 1.5f, s.next1d() * 3 - 1.5f, s.next1d() * 2 - 1);
        const Vec3f d = square_to_uniform_sphere(s.next2d());
        const Vec3f ou(g.sigma_t.to_unit.point(Vec3d(o))), du(g.sigma_t.to_unit.vector(Vec3d(d)));
        MajorantIterator it(*g.majorants, ou, du, 0, 4);
        MajorantSegment seg;
        float last = -1;
        while (it.next(seg)) {
            EXPECT_GE(seg.t0, last);
            last = seg.t1;
            for (float f : {0.0f, 0.37f, 0.999f}) {
                const float t = seg.t0 + (seg.t1 - seg.t0) * f;
                EXPECT_LE(max_component(medium_coefficients(m, o + d * t).sigma_t), seg.sigma_maj);
            }
        }
    }
}

// ---- grids ----------------------------------------------------------------------------------

TEST(VoxelGrid, TrilinearLookupsAtCentresBetweenThemAndOutside) {
    VoxelGrid g;
    g.res = {2, 2, 2};
    g.data = {0, 1, 2, 3, 4, 5, 6, 7};  // value = x + 2 y + 4 z
    // Voxel centres at 1/4 and 3/4.
    EXPECT_FLOAT_EQ(g.lookup({0.25f, 0.25f, 0.25f}).x, 0);
    EXPECT_FLOAT_EQ(g.lookup({0.75f, 0.75f, 0.75f}).x, 7);
    EXPECT_FLOAT_EQ(g.lookup({0.5f, 0.5f, 0.5f}).x, 3.5f);
    EXPECT_FLOAT_EQ(g.lookup({0.5f, 0.25f, 0.75f}).x, 0.5f + 4);
    // Between a centre and the face: the edge value (clamp), as Mitsuba 3's texture.
    EXPECT_FLOAT_EQ(g.lookup({0.1f, 0.25f, 0.25f}).x, 0);
    EXPECT_FLOAT_EQ(g.lookup({1.0f, 0.75f, 0.75f}).x, 7);
    // Outside the unit cube: nothing.
    EXPECT_EQ(g.lookup({1.01f, 0.5f, 0.5f}), Rgb(0.0f));
    EXPECT_EQ(g.lookup({0.5f, -0.01f, 0.5f}), Rgb(0.0f));
    g.nearest = true;
    EXPECT_FLOAT_EQ(g.lookup({0.6f, 0.4f, 0.9f}).x, 1 + 0 + 4);
}

class GridFiles : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-media-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

TEST_F(GridFiles, VolRoundTrip) {
    const VoxelGrid g = test_grid();
    write_vol_file(path("a.vol"), g);
    EXPECT_EQ(fs::file_size(path("a.vol")), 48 + 4 * g.data.size());
    const VoxelGrid back = read_vol_file(path("a.vol"));
    EXPECT_EQ(back.res, g.res);
    EXPECT_EQ(back.channels, 3);
    EXPECT_EQ(back.data, g.data);
}

std::string expect_grid_error(const std::function<void()>& f) {
    try {
        f();
    } catch (const GridFileError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no GridFileError";
    return "";
}

TEST_F(GridFiles, BadVolFilesNameTheFileAndTheProblem) {
    VoxelGrid g = test_grid();
    write_vol_file(path("good.vol"), g);
    std::string bytes;
    {
        std::ifstream in(path("good.vol"), std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    const auto check = [&](const std::string& name, const std::string& content, const std::string& problem) {
        std::ofstream(path(name), std::ios::binary) << content;
        const std::string message = expect_grid_error([&] { read_vol_file(path(name)); });
        EXPECT_NE(message.find(path(name)), std::string::npos) << message;
        EXPECT_NE(message.find(problem), std::string::npos) << message;
    };
    check("truncated.vol", bytes.substr(0, bytes.size() - 3), "truncated");
    check("header.vol", bytes.substr(0, 30), "truncated");
    check("magic.vol", "VOX" + bytes.substr(3), "begin with the bytes 'VOL'");
    std::string version = bytes;
    version[3] = 2;
    check("version.vol", version, "version 2");
    std::string dims = bytes;
    dims[8] = 7;  // xres 5 -> 7: the data no longer fits
    check("dims.vol", dims, "truncated");
    dims[8] = 0;
    check("zero.vol", dims, "invalid dimensions 0x4x3");
    dims[8] = 4;  // fewer voxels than data
    check("trailing.vol", dims, "wrong dimensions");
    std::string neg = bytes;
    const float minus = -0.5f;
    std::memcpy(neg.data() + 48 + 4 * 7, &minus, 4);  // voxel (2, 0, 0) channel 1
    check("negative.vol", neg, "voxel (2, 0, 0) channel 1 is -0.5");
    std::string channels = bytes;
    channels[20] = 2;
    check("channels.vol", channels, "channel count 2");
    EXPECT_NE(expect_grid_error([&] { read_vol_file(path("missing.vol")); }).find("no such file"), std::string::npos);
    EXPECT_NE(expect_grid_error([&] { read_vol_file(dir_.string()); }).find("not a regular file"), std::string::npos);
}

// A .vdb grid written here with OpenVDB (the project's own small test file, made at test time)
// reads back to the same values at the same world positions.
TEST_F(GridFiles, VdbGridReadsBackInItsWorldSpace) {
    VoxelGrid g;
    g.res = {6, 5, 4};
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 6; ++x) g.data.push_back(x == 0 && y == 0 ? 0.0f : 1.0f + float(x) + 2.0f * float(y) + 3.0f * float(z));
    write_vdb_file(path("test.vdb"), g, "density", 0.5);
    const VdbGrid v = read_vdb_file(path("test.vdb"));
    // The column x = y = 0 is 0, so inactive in the file; it reads back as 0.
    const Volume vol = Volume::of_grid(v.grid, v.unit_to_world);
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 6; ++x) {
                const Vec3f world(0.5f * float(x), 0.5f * float(y), 0.5f * float(z));  // OpenVDB: voxel (i,j,k) at (i,j,k) * size
                EXPECT_NEAR(vol.eval(world).x, g.at(x, y, z, 0), 1e-4) << x << " " << y << " " << z;
            }
    // Between voxel centres: the trilinear mix of the eight around it.
    EXPECT_NEAR(vol.eval({0.75f, 0.75f, 0.75f}).x, 1 + 1.5f + 2 * 1.5f + 3 * 1.5f, 1e-4);
    // A grid chosen by name, and a wrong name listing the file's grids.
    EXPECT_NO_THROW(read_vdb_file(path("test.vdb"), "density"));
    const std::string m = expect_grid_error([&] { read_vdb_file(path("test.vdb"), "smoke"); });
    EXPECT_NE(m.find("no grid named 'smoke'; its grids: density"), std::string::npos) << m;
    std::ofstream(path("junk.vdb")) << "not a vdb";
    const std::string junk = expect_grid_error([&] { read_vdb_file(path("junk.vdb")); });
    EXPECT_NE(junk.find(path("junk.vdb")), std::string::npos) << junk;
}

// Hostile .vdb files made from a good one: OpenVDB trusts a file's layout, and looped forever on
// a grid offset pointing backwards and on a file cut inside its header, and grew by gigabytes on
// a flipped count or length; each is refused with the file and its problem, before OpenVDB reads
// it or (the tree's counts) as its reading reaches the end of the file.
TEST_F(GridFiles, VdbFilesWithABrokenLayoutAreRefusedBeforeOpenVdbReadsThem) {
    VoxelGrid g;
    g.res = {3, 3, 3};
    g.data.assign(27, 1.0f);
    write_vdb_file(path("good.vdb"), g, "density", 0.5);
    std::ifstream in(path("good.vdb"), std::ios::binary);
    const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // The first grid descriptor: after the header (57 bytes), no metadata (4), the grid count (4),
    // then the name, type and parent name (each a 4-byte length and its bytes), then the grid's
    // three positions.
    size_t at = 65;
    for (int k = 0; k < 3; ++k) {
        uint32_t n;
        std::memcpy(&n, good.data() + at, 4);
        at += 4 + n;
    }
    const auto with = [&](size_t offset, int64_t value) {
        std::string bad = good;
        std::memcpy(bad.data() + offset, &value, 8);
        return bad;
    };
    const auto with32 = [&](size_t offset, uint32_t value) {
        std::string bad = good;
        std::memcpy(bad.data() + offset, &value, 4);
        return bad;
    };
    // The grid's data: its compression flags (4 bytes), its metadata count, then name, type, size
    // and value of each entry; after the metadata its transform (a map name, 120 bytes of a
    // uniform scale map), then the tree: buffer count, background, tile count, child count.
    const size_t grid = at + 24, map = good.find("UniformScaleMap");
    const auto after = [&](const std::string& text) { return good.find(text) + text.size(); };
    ASSERT_NE(map, std::string::npos);
    ASSERT_NE(good.find("__delayedload"), std::string::npos);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {with(at, -5), "grid 1 spans bytes -5"},                        // (it looped forever)
        {with(at, int64_t(grid) + 4), "grid 1 spans bytes"},             // (read as if it were there)
        {with32(grid + 4, 0x7ffffff0), "grid 1 claims 2147483632 metadata entries"},  // (gigabytes)
        {with32(grid + 8, 1u << 30), "its grid metadata name claims 1073741824 bytes"},
        {with32(after("vec3i"), 500), "(vec3i) has 500 bytes, not 12"},  // (out of step: gigabytes)
        {with32(after("__delayedload") + 4, 0x7fffffff), "claims 2147483647 leaf nodes"},
        {with32(map + 15 + 120 + 12, 1u << 30), "ends inside its grid 'density''s internal node's child mask"},  // (gigabytes)
        {with32(map + 15 + 120, 2), "tree has 2 buffers, not 1"},
        {with(at + 8, int64_t(1) << 40), "not within its part of the file"},
        {with(at + 16, int64_t(good.size()) + 1), "not within its part of the file"},
        {good.substr(0, 40), "it ends inside its UUID"},                // (it looped forever)
        {good.substr(0, at + 4), "it ends inside its grid position"},
        {with(8, 300), "file format version 300"},
    };
    for (size_t i = 0; i < cases.size(); ++i) {
        const std::string file = path(fmt::format("bad{}.vdb", i));
        std::ofstream(file, std::ios::binary) << cases[i].first;
        const std::string m = expect_grid_error([&] { read_vdb_file(file); });
        EXPECT_NE(m.find(file), std::string::npos) << m;
        EXPECT_NE(m.find(cases[i].second), std::string::npos) << i << ": " << m;
    }
    EXPECT_NO_THROW(read_vdb_file(path("good.vdb")));
}

// .vdb files as other programs write them (OpenVDB itself, tests/tools/vdb_fixture_writer.cpp):
// half floats, zip and no compression, vec3s values, several grids (one of a type pathlab does
// not read: only the chosen grid is read), an instance sharing another grid's tree with its own
// transform, tiles and inactive values. Each reads back to the writer's values at their world
// positions, through the same checks of every count and size as pathlab's own files.
TEST_F(GridFiles, VdbFilesOfOtherWritersReadBack) {
    ASSERT_EQ(std::system(fmt::format("'{}' '{}'", PATHLAB_VDB_FIXTURE_WRITER, dir_.string()).c_str()), 0);
    const auto value = [](int i, int j, int k) { return 0.25f * float((i + 5) + 2 * (j + 3) + 3 * (k + 2)) + 0.25f; };
    // Voxel (i, j, k) of a grid of voxels `voxel` wide is at world (i, j, k) * voxel.
    const auto expect_values = [&](const std::string& file, const std::string& grid, double voxel, int channels) {
        SCOPED_TRACE(file + " " + grid);
        const VdbGrid v = read_vdb_file(path(file), grid);
        ASSERT_EQ(v.grid.channels, channels);
        EXPECT_EQ(v.grid.res, (std::array<int, 3>{20, 12, 8}));
        const Volume vol = Volume::of_grid(v.grid, v.unit_to_world);
        for (int k = -2; k <= 5; ++k)
            for (int j = -3; j <= 8; ++j)
                for (int i = -5; i <= 14; i += 3) {
                    const Vec3f world = Vec3f(float(i), float(j), float(k)) * float(voxel);
                    const Vec3f got = vol.eval(world);
                    EXPECT_NEAR(got.x, value(i, j, k), 1e-4) << i << " " << j << " " << k;
                    if (channels == 3) EXPECT_NEAR(got.z, 3 * value(i, j, k), 1e-4) << i << " " << j << " " << k;
                }
    };
    expect_values("half.vdb", "", 0.5, 1);
    expect_values("zip.vdb", "", 0.5, 3);
    expect_values("raw.vdb", "", 0.5, 1);
    expect_values("multi.vdb", "", 0.5, 1);
    expect_values("multi.vdb", "smoke", 1.0, 1);
    const std::string labels = expect_grid_error([&] { read_vdb_file(path("multi.vdb"), "labels"); });
    EXPECT_NE(labels.find("grid 'labels' holds int32 values; pathlab reads float and vec3s grids"), std::string::npos) << labels;
    // The tiles file: a 16^3 tile of 2 from the origin and one active voxel of 5 at (20, 1, 1);
    // the inactive voxels between (-1 and 3 in the file) read as 0.
    const VdbGrid t = read_vdb_file(path("tiles.vdb"));
    EXPECT_EQ(t.grid.res, (std::array<int, 3>{21, 16, 16}));
    EXPECT_EQ(t.grid.at(0, 0, 0, 0), 2.0f);
    EXPECT_EQ(t.grid.at(15, 15, 15, 0), 2.0f);
    EXPECT_EQ(t.grid.at(20, 1, 1, 0), 5.0f);
    EXPECT_EQ(t.grid.at(17, 0, 0, 0), 0.0f);
    EXPECT_EQ(t.grid.at(18, 0, 0, 0), 0.0f);
}

}  // namespace
}  // namespace pathlab::test
