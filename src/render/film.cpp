#include "render/film.hpp"

#include <cmath>

namespace pathlab {

Image Film::mean() const {
    Image img(width_, height_);
    for (size_t i = 0; i < sum_.size(); ++i)
        if (count_[i]) img[i] = Rgb(sum_[i] / double(count_[i]));
    return img;
}

Image Film::standard_error() const {
    Image img(width_, height_);
    for (size_t i = 0; i < sum_.size(); ++i) {
        const double n = count_[i];
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
