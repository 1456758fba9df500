#include "render/film.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace pathlab {

void Film::add_pass(const Vec3d* values, size_t count) {
    if (count != pixels_.size()) throw std::invalid_argument("Film::add_pass: the pass has another size");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) add(i, values[i]);
    });
}

void Film::merge(const Film& other) {
    if (other.width_ != width_ || other.height_ != height_) throw std::invalid_argument("Film::merge: films of different sizes");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels_.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) pixels_[i].merge(other.pixels_[i]);
    });
}

bool Film::identical(const Film& other) const {
    return width_ == other.width_ && height_ == other.height_ &&
           std::memcmp(pixels_.data(), other.pixels_.data(), pixels_.size() * sizeof(PixelSums)) == 0;
}

Film Film::from_sums(int width, int height, std::vector<Vec3d> sum, std::vector<Vec3d> sumsq, std::vector<uint64_t> count) {
    const size_t n = size_t(width) * size_t(height);
    if (sum.size() != n || sumsq.size() != n || count.size() != n) throw std::invalid_argument("Film::from_sums: sizes differ");
    Film f(width, height);
    for (size_t i = 0; i < n; ++i) {
        PixelSums& p = f.pixels_[i];
        for (int c = 0; c < 3; ++c) {
            exact::deposit(p.sum[c], p.top[c], sum[i][c]);
            exact::deposit(p.sumsq[c], p.top[3 + c], sumsq[i][c]);
        }
        p.count = count[i];
    }
    return f;
}

Image Film::mean() const {
    Image img(width_, height_);
    // In parallel (each pixel on its own, so the same bytes whatever the threads): a display
    // server takes the mean several times a second.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels_.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i)
            if (pixels_[i].count) img[i] = Rgb(pixels_[i].sum_value() / double(pixels_[i].count));
    });
    return img;
}

Image Film::standard_error() const {
    Image img(width_, height_);
    for (size_t i = 0; i < pixels_.size(); ++i) {
        const double n = double(pixels_[i].count);
        if (n < 2) continue;
        const Vec3d m = pixels_[i].sum_value() / n, sq = pixels_[i].sumsq_value();
        for (int c = 0; c < 3; ++c) {
            const double var = std::max(0.0, (sq[c] - n * m[c] * m[c]) / (n - 1));
            img[i][c] = float(std::sqrt(var / n));
        }
    }
    return img;
}

}  // namespace pathlab
