// Per-pixel accumulation of samples in double precision: sum, sum of squares and count, so
// the image is the mean and every pixel also carries the standard error of that mean.
#pragma once

#include <cstdint>
#include <vector>

#include "image/image.hpp"

namespace pathlab {

class Film {
public:
    Film() = default;
    Film(int width, int height)
        : width_(width), height_(height), sum_(size_t(width) * size_t(height)), sumsq_(sum_.size()), count_(sum_.size()) {}

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixel_count() const { return sum_.size(); }

    // Not synchronised: during a pass each pixel is owned by exactly one thread.
    void add(size_t pixel, const Rgb& v) {
        const Vec3d d(v);
        sum_[pixel] += d;
        sumsq_[pixel] += d * d;
        ++count_[pixel];
    }
    uint32_t count(size_t pixel) const { return count_[pixel]; }

    Image mean() const;
    // Standard error of each pixel's mean, sqrt(s^2 / n) with the unbiased sample variance s^2.
    Image standard_error() const;

private:
    int width_ = 0, height_ = 0;
    std::vector<Vec3d> sum_, sumsq_;
    std::vector<uint32_t> count_;
};

}  // namespace pathlab
