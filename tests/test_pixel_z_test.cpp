// Mitsuba 3's render-test judge (judge/pixel_z_test.hpp, `pathlab compare --z-test`): an image
// made of `spp` samples of a known per-sample variance around the reference passes; the same
// image 10% too bright, or judged with ten times the samples it has, fails; a NaN channel fails
// its own test.
#include <gtest/gtest.h>

#include <cmath>

#include "judge/pixel_z_test.hpp"
#include "samplers/sampler.hpp"

namespace pathlab::test {
namespace {

// A W x W reference with a gradient, a per-sample variance image, and a render: the mean of
// `spp` samples, each the reference times (1 + 0.5 u), u uniform in [-1, 1] (variance
// (ref / 2)^2 / 3 in each channel before the XYZ matrix; the variance image says so in RGB, as
// Mitsuba's does).
struct Case {
    Image ref, var, img;
};
Case make_case(int w, uint64_t spp, float bias, uint64_t seed) {
    Case c{Image(w, w), Image(w, w), Image(w, w)};
    Sampler rng(seed, 0, 0);
    for (int y = 0; y < w; ++y)
        for (int x = 0; x < w; ++x) {
            const Rgb r(0.2f + 0.6f * float(x) / float(w), 0.5f, 0.1f + 0.8f * float(y) / float(w));
            c.ref.at(x, y) = r;
            c.var.at(x, y) = r * r * (0.25f / 3);
            Rgb sum(0.0f);
            for (uint64_t s = 0; s < spp; ++s) sum += r * (1 + 0.5f * (2 * rng.next1d() - 1));
            c.img.at(x, y) = sum / float(spp) * (1 + bias);
        }
    return c;
}

TEST(PixelZTest, PassesAnUnbiasedImageAndFailsABiasedOne) {
    PixelZTestOptions o;
    o.spp = 64;
    const Case good = make_case(48, o.spp, 0, 1);
    const PixelZTest t = pixel_z_test(good.img, good.ref, good.var, o);
    EXPECT_TRUE(t.pass) << t.pass_fraction();
    EXPECT_EQ(t.tested, 48u * 48u * 3u);
    EXPECT_NEAR(t.alpha_per_test, 1 - std::pow(0.99, 1.0 / (48 * 48)), 1e-12);  // Sidak
    EXPECT_NEAR(t.mean_relative_diff, 0, 0.01);
    // 10% too bright: with a relative per-sample standard deviation near 0.29 and 64 samples each
    // pixel-channel is off by about 3 standard errors, so a few percent of them cross the Sidak
    // level (z about 4.6) and the image fails. (The judge is Mitsuba's: a 1% bias at these
    // settings would pass; it looks for errors of a few standard errors per pixel.)
    const Case bright = make_case(48, o.spp, 0.10f, 1);
    const PixelZTest b = pixel_z_test(bright.img, bright.ref, bright.var, o);
    EXPECT_FALSE(b.pass) << b.pass_fraction();
    EXPECT_GT(b.mean_relative_diff, 0.09);
    // The same unbiased image, judged as if it had 10x the samples (its noise is then too large).
    o.spp = 640;
    EXPECT_FALSE(pixel_z_test(good.img, good.ref, good.var, o).pass);
}

TEST(PixelZTest, NanPixelsFailAndSizesMustAgree) {
    PixelZTestOptions o;
    o.spp = 64;
    Case c = make_case(16, o.spp, 0, 2);
    EXPECT_TRUE(pixel_z_test(c.img, c.ref, c.var, o).pass);
    c.img.at(3, 4).y = std::nanf("");
    const PixelZTest t = pixel_z_test(c.img, c.ref, c.var, o);
    EXPECT_GE(t.tested - t.passed, 1u);  // the NaN channel (one of 768: the image as a whole still passes, as in Mitsuba)
    EXPECT_EQ(t.min_p_value, 0.0);
    EXPECT_THROW(pixel_z_test(Image(4, 4), Image(4, 5), Image(4, 4), o), std::invalid_argument);
    o.spp = 0;
    EXPECT_THROW(pixel_z_test(c.img, c.ref, c.var, o), std::invalid_argument);
}

TEST(PixelZTest, XyzIsMitsubasMatrix) {
    const Rgb white = srgb_to_xyz(Rgb(1.0f));
    EXPECT_NEAR(white.x, 0.950456, 1e-5);  // D65
    EXPECT_NEAR(white.y, 1.0, 1e-5);
    EXPECT_NEAR(white.z, 1.088754, 1e-5);
}

}  // namespace
}  // namespace pathlab::test
