// The film: per-pixel accumulation of samples in double precision (sum, sum of squares and
// count), so the image is the mean and every pixel also carries the standard error of it.
//
// A "sample" of a pixel is one independent estimate of its value. Pixel integrators add one
// per camera path (add); integrators that splat onto arbitrary pixels collect a whole pass in
// a PassImage (render/pass_image.hpp) and add it as one sample of every pixel (add_pass): the
// standard error is then that of the batch means over passes, which is exact because passes
// are independent.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "image/image.hpp"
#include "core/properties.hpp"

namespace pathlab {

class Film {
public:
    Film() = default;
    Film(int width, int height)
        : width_(width), height_(height), sum_(size_t(width) * size_t(height)), sumsq_(sum_.size()), count_(sum_.size()) {}

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixel_count() const { return sum_.size(); }

    // One sample of one pixel. Not synchronised: during a pass each pixel is owned by one thread.
    void add(size_t pixel, const Rgb& v) { add(pixel, Vec3d(v)); }
    void add(size_t pixel, const Vec3d& d) {
        sum_[pixel] += d;
        sumsq_[pixel] += d * d;
        ++count_[pixel];
    }
    // One sample of every pixel: values[p] is pixel p's estimate from one pass.
    void add_pass(const std::vector<Vec3d>& values) { add_pass(values.data(), values.size()); }
    void add_pass(const Vec3d* values, size_t count);

    uint64_t count(size_t pixel) const { return count_[pixel]; }
    const Vec3d& sum(size_t pixel) const { return sum_[pixel]; }
    const Vec3d& sum_of_squares(size_t pixel) const { return sumsq_[pixel]; }

    // Adds another film's samples (another range of sample indices of the same render).
    void merge(const Film& other);
    // A film with the given sums, squares and counts (a saved render taken up again); throws
    // std::invalid_argument when the sizes disagree.
    static Film from_sums(int width, int height, std::vector<Vec3d> sum, std::vector<Vec3d> sumsq, std::vector<uint64_t> count);

    Image mean() const;
    // Standard error of each pixel's mean, sqrt(s^2 / n) with the unbiased sample variance s^2.
    Image standard_error() const;

private:
    int width_ = 0, height_ = 0;
    std::vector<Vec3d> sum_, sumsq_;
    std::vector<uint64_t> count_;
};

// The scene-file film (Mitsuba's hdrfilm). Its <rfilter> is the reconstruction filter
// (core/reconstruction_filter.hpp; box with radius 0.5 is this film as it is: each sample in
// its own pixel); the others spread samples through render/pixel_filter.hpp.
inline const PluginInfo& hdrfilm_plugin() {
    static const PluginInfo info{
        "film", "hdrfilm", "the image: its size, window and reconstruction filter (<rfilter>: box, tent, gaussian, mitchell, catmullrom, lanczos)",
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
