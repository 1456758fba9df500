// The scrambled Sobol sampler: stratification (net properties) per dimension, uniformity over
// pixels, and an image that converges to the independent sampler's.
#include <gtest/gtest.h>

#include <vector>

#include "chi2.hpp"
#include "judge/image_statistics.hpp"
#include "render_helpers.hpp"

namespace pathlab {
namespace {

// True when the points form a (0,m,2)-net in base 2: for every split a + b = m, each of the
// 2^a x 2^b elementary intervals holds exactly one of the 2^m points.
bool is_net(const std::vector<Vec2f>& points, int m) {
    for (int a = 0; a <= m; ++a) {
        const int nx = 1 << a, ny = 1 << (m - a);
        std::vector<int> count(size_t(nx) * size_t(ny), 0);
        for (const Vec2f& p : points) ++count[size_t(int(p.y * float(ny))) * size_t(nx) + size_t(int(p.x * float(nx)))];
        for (int c : count)
            if (c != 1) return false;
    }
    return true;
}

// Points of dimension `dim` (the dim-th call on each sample, earlier calls being next2d) of the
// first 2^m samples of one pixel.
std::vector<Vec2f> pixel_points(uint64_t seed, uint64_t pixel, int dim, int m) {
    std::vector<Vec2f> points;
    for (uint64_t s = 0; s < (uint64_t(1) << m); ++s) {
        Sampler sampler(seed, pixel, s, SamplerKind::Sobol);
        for (int d = 0; d < dim; ++d) sampler.next2d();
        points.push_back(sampler.next2d());
    }
    return points;
}

TEST(SobolSampler, EveryPowerOfTwoPrefixOfEveryDimensionIsANet) {
    for (uint64_t pixel : {0u, 1u, 12345u})
        for (int dim : {0, 1, 5})
            for (int m = 0; m <= 12; ++m) EXPECT_TRUE(is_net(pixel_points(9, pixel, dim, m), m)) << pixel << " " << dim << " " << m;
}

TEST(SobolSampler, OneDimensionalPrefixesAreStratified) {
    for (int m = 0; m <= 12; ++m) {
        std::vector<int> count(size_t(1) << m, 0);
        for (uint64_t s = 0; s < (uint64_t(1) << m); ++s) {
            Sampler sampler(3, 77, s, SamplerKind::Sobol);
            sampler.next2d();
            ++count[size_t(sampler.next1d() * float(1 << m))];
        }
        for (int c : count) ASSERT_EQ(c, 1) << "m = " << m;
    }
}

// Over many pixels the same sample's point is uniform in the square (pixels are scrambled
// independently), and pairs of dimensions of one pixel are not correlated (padding): chi-square.
TEST(SobolSampler, PointsAreUniformAcrossPixelsAndDimensionsAreIndependent) {
    constexpr int kBins = 16, kPoints = 1 << 16;
    std::vector<double> across(kBins * kBins, 0), pairs(kBins * kBins, 0);
    for (int i = 0; i < kPoints; ++i) {
        Sampler a(5, uint64_t(i), 3, SamplerKind::Sobol);
        const Vec2f p = a.next2d();
        ++across[size_t(int(p.y * kBins)) * kBins + size_t(int(p.x * kBins))];
        // Pixel 1's sample i: first coordinate of dimension 0 against that of dimension 1.
        Sampler b(5, 1, uint64_t(i), SamplerKind::Sobol);
        const float x0 = b.next2d().x, x1 = b.next2d().x;
        ++pairs[size_t(int(x1 * kBins)) * kBins + size_t(int(x0 * kBins))];
    }
    std::vector<double> expected(kBins * kBins, double(kPoints) / (kBins * kBins));
    for (auto* v : {&across, &pairs, &expected}) v->push_back(0);  // the (empty) rejection cell
    const test::Chi2Result u = test::chi2_from_counts(across, expected), p = test::chi2_from_counts(pairs, expected);
    EXPECT_GT(u.p_value, test::suite_chi2_alpha()) << u.describe();
    EXPECT_GT(p.p_value, test::suite_chi2_alpha()) << p.describe();
}

TEST(SobolSampler, ImagesAgreeWithIndependentSampling) {
    for (int scene : {3, 7}) {
        const SceneDescription d = make_builtin_scene(scene);
        const auto s = Scene::build(d);
        const auto est = find_integrator("pt-mis")->make({});
        RenderSettings rs;
        rs.width = rs.height = 16;
        rs.spp = 2048;
        rs.seed = 21;
        const RenderResult independent = render(*s, *est, rs);
        rs.sampler = SamplerKind::Sobol;
        rs.seed = 22;
        const RenderResult sobol = render(*s, *est, rs);
        const AgreementResult a = test_agreement(sobol.film.mean(), sobol.film.standard_error(), independent.film.mean(),
                                                 independent.film.standard_error());
        EXPECT_TRUE(a.agree) << "scene " << scene << ": " << a.describe();
    }
}

}  // namespace
}  // namespace pathlab
