// Statistical agreement of two Monte Carlo images that carry per-pixel standard errors.
//
// For every pixel and channel, z = (a - b) / sqrt(se_a^2 + se_b^2). If both images estimate
// the same expectation, z is approximately standard normal (per-pixel means of many
// independent samples), and independent across pixels. Two checks, per channel:
//  - outliers: the number of pixels with |z| > z_pixel (two-sided level `pixel_alpha`) is
//    Binomial(n, pixel_alpha); more than its (1 - family_alpha) quantile fails. Catches local
//    errors (a missing highlight, a wrong shadow).
//  - bias: sum(z) / sqrt(n) over the n pixels with a non-zero error is standard normal; beyond the two-sided (family_alpha) quantile
//    fails. Catches small errors spread over the whole image (a few percent of radiance).
// The levels are split over the three channels (Bonferroni), so `family_alpha` is the
// probability of a false alarm for the whole comparison.
//
// A pixel where exactly one image has zero sample variance needs care. If that image's value
// is not 0, all its samples gave the same value (an emitter seen directly by a path tracer):
// the value is exact and z is the other image's error over its own standard error. If the
// value is 0, the estimator may simply not have found light there yet: an estimator that
// finds a light only with probability 1e-5 per sample (a grazing view of a small emitter)
// usually draws no hit at all, and then reports a mean of 0 with a standard error of 0. Such a
// pixel-channel is "unresolved" and excused when its difference is below
// `negligible_fraction` of the image's mean in that channel, and counts as an outlier
// (infinite z) otherwise; more than `max_unresolved_fraction` excused pixel-channels fail the
// comparison. An estimator that is black where light matters is therefore not excused. Where
// both images have zero variance, they must be equal.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "image/image.hpp"

namespace pathlab {

struct AgreementOptions {
    double pixel_alpha = 1e-3;
    double family_alpha = 1e-4;
    double negligible_fraction = 0.01;
    double max_unresolved_fraction = 0.05;
    // Pixels left out of the comparison (non-zero entries), e.g. those a light tracer cannot
    // render by design (judge/specular_mask.hpp); null: none.
    const std::vector<uint8_t>* excluded = nullptr;
};

struct AgreementResult {
    bool agree = true;
    long pixels = 0;             // pixels x channels tested
    long outliers = 0;           // worst channel's count of |z| > z_pixel
    long allowed_outliers = 0;   // per channel
    long unresolved = 0;         // pixel-channels excused (see above)
    long excluded = 0;           // pixels left out (AgreementOptions::excluded)
    double max_abs_z = 0;
    double bias_z[3] = {0, 0, 0};  // pooled difference over its standard error, per channel
    double bias_limit = 0;
    std::string describe() const;
};

// An empty se_b (no pixels) means b is exact (a closed form): only a's errors count.
AgreementResult test_agreement(const Image& a, const Image& se_a, const Image& b, const Image& se_b,
                               const AgreementOptions& options = {});

// Two-sided standard-normal quantile: |Z| > normal_quantile_two_sided(alpha) with prob. alpha.
double normal_quantile_two_sided(double alpha);
// Smallest k with P(Binomial(n, p) > k) <= alpha.
long binomial_upper_quantile(long n, double p, double alpha);

}  // namespace pathlab
