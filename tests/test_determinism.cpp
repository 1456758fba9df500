// The image is a pure function of (seed, pixel, sample index): thread count and tile size
// change nothing, bit for bit.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "render_helpers.hpp"

namespace pathlab::test {
namespace {

RenderResult render_with(int threads, int tile_size, uint64_t seed = 5, SamplerKind sampler = SamplerKind::Independent) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const auto scene = Scene::build(make_builtin_scene(3));
    const auto estimator = find_integrator("direct-light")->make({});
    RenderSettings rs;
    rs.width = 96;
    rs.height = 64;
    rs.spp = 6;
    rs.seed = seed;
    rs.tile_size = tile_size;
    rs.sampler = sampler;
    return render(*scene, *estimator, rs);
}

TEST(Determinism, OneAndTwoThreadsGiveBitIdenticalImages) {
    const RenderResult one = render_with(1, 16), two = render_with(2, 16);
    EXPECT_TRUE(bit_identical(one.film.mean(), two.film.mean()));
    EXPECT_TRUE(bit_identical(one.film.standard_error(), two.film.standard_error()));
    EXPECT_EQ(one.stats.rays, two.stats.rays);
}

TEST(Determinism, SobolSamplingIsDeterministicToo) {
    const RenderResult one = render_with(1, 16, 5, SamplerKind::Sobol), two = render_with(2, 9, 5, SamplerKind::Sobol);
    EXPECT_TRUE(bit_identical(one.film.mean(), two.film.mean()));
    EXPECT_FALSE(bit_identical(one.film.mean(), render_with(2, 16, 5).film.mean()));  // it is another sampler
}

TEST(Determinism, TileSizeDoesNotChangeTheImage) {
    EXPECT_TRUE(bit_identical(render_with(2, 7).film.mean(), render_with(2, 32).film.mean()));
}

TEST(Determinism, TheSeedDoesChangeTheImage) {
    EXPECT_FALSE(bit_identical(render_with(2, 16, 5).film.mean(), render_with(2, 16, 6).film.mean()));
}

}  // namespace
}  // namespace pathlab::test
