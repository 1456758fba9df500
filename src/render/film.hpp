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

// The scene-file film (Mitsuba 3's hdrfilm): pathlab's film is a box filter, one pixel wide.
inline const PluginInfo& hdrfilm_plugin() {
    static const PluginInfo info{"film", "hdrfilm", "the image: its size (the outputs' formats come from -o)",
                                 {{"width", ParamType::Integer, "768", "pixels"}, {"height", ParamType::Integer, "576", "pixels"}}};
    return info;
}

}  // namespace pathlab
