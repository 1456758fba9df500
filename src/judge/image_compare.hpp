// Statistics of the difference between two linear images A and B (B taken as the reference):
// the per-channel signed mean difference mean(A - B) (the course grader's measure), the mean
// absolute error, the RMSE, the relative MSE mean((A - B)^2 / (B^2 + eps)) with eps = 0.01
// (so that black reference pixels do not dominate; the usual choice in denoising papers), and
// the largest absolute difference. Pixel-channels that are NaN or infinite in either image are
// counted and left out of every statistic.
#pragma once

#include <array>
#include <stdexcept>
#include <string>

#include "image/image.hpp"

namespace pathlab {

struct ImageSizeMismatch : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

struct ChannelStatistics {
    double mean_diff = 0;  // mean of A - B
    double mae = 0;        // mean of |A - B|
    double rmse = 0;       // sqrt(mean of (A - B)^2)
    double relmse = 0;     // mean of (A - B)^2 / (B^2 + eps)
    double max_abs_diff = 0;
};

struct ImageDifference {
    int width = 0, height = 0;
    std::array<ChannelStatistics, 3> channel;  // R, G, B
    ChannelStatistics all;                     // over all three channels
    long compared = 0;                         // finite pixel-channel pairs used
    long nan_a = 0, inf_a = 0, nan_b = 0, inf_b = 0;  // non-finite pixel-channels per image
    long non_finite() const { return nan_a + inf_a + nan_b + inf_b; }
    // The largest |mean difference| over the three channels (what --threshold tests by default).
    double worst_mean_diff() const;
};

constexpr double kRelMseEpsilon = 0.01;

// Throws ImageSizeMismatch (naming both sizes) when the images differ in size.
ImageDifference compare_images(const Image& a, const Image& b);

// A statistic selected by name, for --threshold: "mean" (worst channel's |mean difference|),
// "mae", "rmse", "relmse", "max" (over all channels). Returns false for an unknown name.
bool image_metric(const ImageDifference& d, const std::string& name, double& value);
constexpr const char* kImageMetricNames = "mean, mae, rmse, relmse, max";

}  // namespace pathlab

namespace pathlab {

// RMSE of `image` against a Monte Carlo reference whose per-pixel standard errors are
// `reference_se` (empty: an exact reference). The reference's own expected squared error,
// mean(se^2), is subtracted from the mean squared difference, so a finite-spp reference
// does not inflate the figure (clamped at 0). Non-finite pixel-channels are left out; a standard
// error that is NaN, infinite or negative throws std::invalid_argument.
double rmse_against_reference(const Image& image, const Image& reference, const Image& reference_se = {});

}  // namespace pathlab
