// The film: per-pixel accumulation of samples (sum, sum of squares and count), so the image is
// the mean and every pixel also carries the standard error of it. The sums are exact and
// order-independent (render/exact_sum.hpp), so a render split into sample ranges (processes,
// checkpoints, merges) adds up to the one-shot film bit for bit.
//
// A "sample" of a pixel is one independent estimate of its value. Pixel integrators add one
// per camera path (add); integrators that splat onto arbitrary pixels collect a whole pass in
// a PassImage (render/pass_image.hpp) and add it as one sample of every pixel (add_pass): the
// standard error is then that of the batch means over passes, which is exact because passes
// are independent.
#pragma once

#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/vec.hpp"
#include "image/image.hpp"
#include "core/properties.hpp"
#include "render/exact_sum.hpp"

namespace pathlab {

// One pixel's accumulators (render/exact_sum.hpp): the sums and the sums of squares of its
// samples, per channel, exact and independent of the order the samples came in, and the count.
// 160 bytes; this layout is what checkpoints store and what MPI reduces (little-endian).
struct PixelSums {
    int64_t sum[3][exact::kBins];
    int64_t sumsq[3][exact::kBins];
    uint64_t count;
    uint8_t top[6];  // windows of sum[0..2], then of sumsq[0..2]
    uint8_t unused[2];

    void add(const Vec3d& v) {
        for (int c = 0; c < 3; ++c) {
            exact::deposit(sum[c], top[c], v[c]);
            exact::deposit(sumsq[c], top[3 + c], v[c] * v[c]);
        }
        ++count;
    }
    void merge(const PixelSums& o) {
        for (int c = 0; c < 3; ++c) {
            exact::merge(sum[c], top[c], o.sum[c], o.top[c]);
            exact::merge(sumsq[c], top[3 + c], o.sumsq[c], o.top[3 + c]);
        }
        count += o.count;
    }
    Vec3d sum_value() const { return {exact::value(sum[0], top[0]), exact::value(sum[1], top[1]), exact::value(sum[2], top[2])}; }
    Vec3d sumsq_value() const {
        return {exact::value(sumsq[0], top[3]), exact::value(sumsq[1], top[4]), exact::value(sumsq[2], top[5])};
    }
};
static_assert(sizeof(PixelSums) == 160 && std::is_trivially_copyable_v<PixelSums>);

class Film {
public:
    Film() = default;
    Film(int width, int height) : width_(width), height_(height), pixels_(size_t(width) * size_t(height), PixelSums{}) {}

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixel_count() const { return pixels_.size(); }

    // One sample of one pixel. Not synchronised: during a pass each pixel is owned by one thread.
    void add(size_t pixel, const Rgb& v) { add(pixel, Vec3d(v)); }
    void add(size_t pixel, const Vec3d& d) { pixels_[pixel].add(d); }
    // One sample of every pixel: values[p] is pixel p's estimate from one pass.
    void add_pass(const std::vector<Vec3d>& values) { add_pass(values.data(), values.size()); }
    void add_pass(const Vec3d* values, size_t count);

    uint64_t count(size_t pixel) const { return pixels_[pixel].count; }
    Vec3d sum(size_t pixel) const { return pixels_[pixel].sum_value(); }
    Vec3d sum_of_squares(size_t pixel) const { return pixels_[pixel].sumsq_value(); }

    // Adds another film's samples (another range of sample indices of the same render, or
    // another seed). Exact: any grouping of the same samples gives the same film, bit for bit.
    void merge(const Film& other);
    // A film with the given sums, squares and counts (a saved render taken up again); throws
    // std::invalid_argument when the sizes disagree.
    static Film from_sums(int width, int height, std::vector<Vec3d> sum, std::vector<Vec3d> sumsq, std::vector<uint64_t> count);

    // The accumulators themselves, for checkpoints and for the reduction across processes.
    PixelSums* data() { return pixels_.data(); }
    const PixelSums* data() const { return pixels_.data(); }
    // True when every pixel equals the other film's (same samples, bit for bit).
    bool identical(const Film& other) const;

    Image mean() const;
    // Standard error of each pixel's mean, sqrt(s^2 / n) with the unbiased sample variance s^2.
    Image standard_error() const;

private:
    int width_ = 0, height_ = 0;
    std::vector<PixelSums> pixels_;
};

// The scene-file film (Mitsuba's hdrfilm). Its <rfilter> is the reconstruction filter
// (core/reconstruction_filter.hpp; box with radius 0.5 is this film as it is: each sample in
// its own pixel); the others spread samples through render/pixel_filter.hpp.
inline const PluginInfo& hdrfilm_plugin() {
    static const PluginInfo info{
        "film", "hdrfilm",
        "the image: its size, window and reconstruction filter (<rfilter>: box, tent, gaussian, mitchell, catmullrom, lanczos; none: "
        "Mitsuba's default, the gaussian)",
        {{"width", ParamType::Integer, "768", "pixels"},
         {"height", ParamType::Integer, "576", "pixels"},
         {"file_format", ParamType::String, "openexr", "openexr, rgbe or pfm: the format of the default output (-o sets others)", "fileFormat"},
         {"pixel_format", ParamType::String, "rgb", "rgb, or rgba (accepted: pathlab writes RGB, no alpha; noted)", "pixelFormat"},
         {"component_format", ParamType::String, "float32", "float32, or float16 (accepted: written as float32, more precise; noted)", "componentFormat"},
         {"crop_offset_x", ParamType::Integer, "0", "the rendered window's left column", "cropOffsetX"},
         {"crop_offset_y", ParamType::Integer, "0", "the rendered window's top row", "cropOffsetY"},
         {"crop_width", ParamType::Integer, "", "the window's width (default: to the right edge)", "cropWidth"},
         {"crop_height", ParamType::Integer, "", "the window's height (default: to the bottom edge)", "cropHeight"},
         {"sample_border", ParamType::Boolean, "false",
          "accepted: a filtered pixel at the border is normalised by the filter's weight inside the image (noted when true)", "highQualityEdges"},
         {"banner", ParamType::Boolean, "false", "accepted and ignored: pathlab never draws a banner into the image"},
         {"attach_log", ParamType::Boolean, "false", "accepted and ignored (Mitsuba 0.6: the log in the EXR header)", "attachLog"}}};
    return info;
}

}  // namespace pathlab
