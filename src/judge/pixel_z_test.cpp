#include "judge/pixel_z_test.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pathlab {

Rgb srgb_to_xyz(const Rgb& c) {
    return Rgb(0.412453f * c.x + 0.357580f * c.y + 0.180423f * c.z, 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z,
               0.019334f * c.x + 0.119193f * c.y + 0.950227f * c.z);
}

PixelZTest pixel_z_test(const Image& image, const Image& reference, const Image& reference_variance,
                        const PixelZTestOptions& options) {
    const auto same_size = [](const Image& a, const Image& b) { return a.width() == b.width() && a.height() == b.height(); };
    if (!same_size(image, reference) || !same_size(image, reference_variance))
        throw std::invalid_argument("the image, the reference and its variance must have the same size");
    if (options.spp == 0) throw std::invalid_argument("the image must have at least one sample per pixel");
    PixelZTest r;
    const double pixels = double(image.pixel_count());
    // 1 - (1 - alpha)^(1/n), without the cancellation of the direct form for large n.
    r.alpha_per_test = -std::expm1(std::log1p(-options.alpha) / pixels);
    double diff = 0, sum = 0;
    for (size_t i = 0; i < image.pixel_count(); ++i) {
        const Rgb x = srgb_to_xyz(image[i]), ref = srgb_to_xyz(reference[i]), var = srgb_to_xyz(reference_variance[i]);
        for (int c = 0; c < 3; ++c) {
            const double v = std::max(double(var[c]), 1e-4);
            const double z = std::abs(double(x[c]) - double(ref[c])) * std::sqrt(double(options.spp) / v);
            const double p = std::erfc(z / std::sqrt(2.0));  // two-sided: 2 (1 - Phi(z)); NaN for a NaN pixel
            ++r.tested;
            if (p > r.alpha_per_test) ++r.passed;  // a NaN fails
            r.min_p_value = std::isnan(p) ? 0.0 : std::min(r.min_p_value, p);
            diff += double(x[c]) - double(ref[c]);
            sum += double(ref[c]);
        }
    }
    r.mean_relative_diff = sum != 0 ? diff / sum : 0.0;
    // Mitsuba: count_nonzero(success) / 3 >= 0.9975 * pixel_count.
    r.pass = double(r.passed) / 3.0 >= options.min_pass * pixels;
    return r;
}

}  // namespace pathlab
