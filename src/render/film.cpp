#include "render/film.hpp"

#include <cmath>
#include <stdexcept>

namespace pathlab {

void Film::add_pass(const Vec3d* values, size_t count) {
    if (count != sum_.size()) throw std::invalid_argument("Film::add_pass: the pass has another size");
    for (size_t i = 0; i < count; ++i) add(i, values[i]);
}

void Film::merge(const Film& other) {
    if (other.width_ != width_ || other.height_ != height_) throw std::invalid_argument("Film::merge: films of different sizes");
    for (size_t i = 0; i < sum_.size(); ++i) {
        sum_[i] += other.sum_[i];
        sumsq_[i] += other.sumsq_[i];
        count_[i] += other.count_[i];
    }
}

Film Film::from_sums(int width, int height, std::vector<Vec3d> sum, std::vector<Vec3d> sumsq, std::vector<uint64_t> count) {
    const size_t n = size_t(width) * size_t(height);
    if (sum.size() != n || sumsq.size() != n || count.size() != n) throw std::invalid_argument("Film::from_sums: sizes differ");
    Film f;
    f.width_ = width, f.height_ = height;
    f.sum_ = std::move(sum), f.sumsq_ = std::move(sumsq), f.count_ = std::move(count);
    return f;
}

Image Film::mean() const {
    Image img(width_, height_);
    for (size_t i = 0; i < sum_.size(); ++i)
        if (count_[i]) img[i] = Rgb(sum_[i] / double(count_[i]));
    return img;
}

Image Film::standard_error() const {
    Image img(width_, height_);
    for (size_t i = 0; i < sum_.size(); ++i) {
        const double n = double(count_[i]);
        if (n < 2) continue;
        const Vec3d m = sum_[i] / n;
        for (int c = 0; c < 3; ++c) {
            const double var = std::max(0.0, (sumsq_[i][c] - n * m[c] * m[c]) / (n - 1));
            img[i][c] = float(std::sqrt(var / n));
        }
    }
    return img;
}

}  // namespace pathlab
