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
#pragma once

#include <string>

#include "core/image.hpp"

namespace pathlab {

struct AgreementOptions {
    double pixel_alpha = 1e-3;
    double family_alpha = 1e-4;
};

struct AgreementResult {
    bool agree = true;
    long pixels = 0;             // pixels x channels tested
    long outliers = 0;           // worst channel's count of |z| > z_pixel
    long allowed_outliers = 0;   // per channel
    double max_abs_z = 0;
    double bias_z[3] = {0, 0, 0};  // sum(z) / sqrt(n) per channel
    double bias_limit = 0;
    std::string describe() const;
};

// se_b may be an all-zero image (b exact). Pixels where both standard errors are zero must
// agree exactly, else they count as outliers with infinite z.
AgreementResult test_agreement(const Image& a, const Image& se_a, const Image& b, const Image& se_b,
                               const AgreementOptions& options = {});

// Two-sided standard-normal quantile: |Z| > normal_quantile_two_sided(alpha) with prob. alpha.
double normal_quantile_two_sided(double alpha);
// Smallest k with P(Binomial(n, p) > k) <= alpha.
long binomial_upper_quantile(long n, double p, double alpha);

}  // namespace pathlab
