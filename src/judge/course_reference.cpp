#include "judge/course_reference.hpp"

#include "judge/image_statistics.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

namespace pathlab {
namespace {
double encode_levels(double linear) { return 255.0 * std::pow(std::clamp(linear, 0.0, 1.0), 1.0 / kCourseGamma); }

// Standard error in grey levels of the encoded block mean m (linear standard error se): the
// difference of the encoding between m -/+ se, which is the slope times se where the
// encoding is smooth and stays finite next to black, where its slope is unbounded. The
// reference's level t bounds the interval from below so a black render block still gets a
// finite error when the reference is not black. A render block whose mean is past white
// (noise next to an emitter) is centred on the reference's level instead, where the
// encoding is not yet flat, so that it does not get a zero error.
double se_levels(double m, double t, double se) {
    if (!(se > 0)) return 0;
    const double centre = std::max(m, t) < 1.0 ? std::max(m, t) : t;
    return 0.5 * (encode_levels(centre + se) - encode_levels(std::max(0.0, centre - se)));
}
}  // namespace

std::string BlockComparison::describe() const {
    return fmt::format("{} blocks ({} pixels): mean |diff| {:.3f}, max |diff| {:.2f}, mean signed diff {:+.3f} grey "
                       "levels{}{}",
                       blocks, pixels_compared, mean_abs_diff, max_abs_diff, mean_signed_diff,
                       mean_noise_levels > 0 ? fmt::format(" (noise explains {:.3f})", mean_noise_levels) : "",
                       z_limit > 0 ? fmt::format("; {} block-channels beyond 1 level + {:.2f} SE{} (worst {:.2f} SE)",
                                                 blocks_beyond_noise, z_limit,
                                                 unresolved_block_channels
                                                     ? fmt::format(", {} of them unresolved", unresolved_block_channels)
                                                     : "",
                                                 worst_excess)
                                   : "");
}

namespace {
// Pixels at most `margin` pixels (Chebyshev distance) from a pixel saturated in `ref`.
std::vector<uint8_t> saturated_mask(const Image8& ref, int margin) {
    const int w = ref.width, h = ref.height;
    std::vector<uint8_t> mask(size_t(w) * size_t(h), 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (ref.at(x, y, 0) != 255 && ref.at(x, y, 1) != 255 && ref.at(x, y, 2) != 255) continue;
            for (int yy = std::max(0, y - margin); yy <= std::min(h - 1, y + margin); ++yy)
                for (int xx = std::max(0, x - margin); xx <= std::min(w - 1, x + margin); ++xx)
                    mask[size_t(yy) * size_t(w) + size_t(xx)] = 1;
        }
    return mask;
}
}  // namespace

BlockComparison compare_with_course_reference(const Image& render, const Image8& ref, const Image& render_se,
                                              int saturated_margin, int block, const std::vector<uint8_t>* also_excluded) {
    if (render.width() != ref.width || render.height() != ref.height)
        throw std::invalid_argument(fmt::format("render is {}x{} but the reference is {}x{}", render.width(),
                                                render.height(), ref.width, ref.height));
    const bool have_se = render_se.pixel_count() == render.pixel_count();
    std::vector<uint8_t> excluded = saturated_mask(ref, std::max(0, saturated_margin));
    if (also_excluded && also_excluded->size() == excluded.size())
        for (size_t i = 0; i < excluded.size(); ++i) excluded[i] |= (*also_excluded)[i];
    BlockComparison out;
    double sum_abs = 0, sum_signed = 0;
    long terms = 0;
    struct BlockError {
        double abs_diff, se;  // grey levels
        double reference;     // the reference's linear block mean
    };
    std::vector<BlockError> block_errors;
    double reference_sum = 0;
    for (int by = 0; by < ref.height; by += block)
        for (int bx = 0; bx < ref.width; bx += block) {
            double mine[3] = {0, 0, 0}, theirs[3] = {0, 0, 0}, var[3] = {0, 0, 0};
            int count = 0;
            for (int y = by; y < std::min(by + block, ref.height); ++y)
                for (int x = bx; x < std::min(bx + block, ref.width); ++x) {
                    if (excluded[size_t(y) * size_t(ref.width) + size_t(x)]) continue;
                    for (int c = 0; c < 3; ++c) {
                        mine[c] += render.at(x, y)[c];
                        theirs[c] += decode_gamma8(ref.at(x, y, c), kCourseGamma);
                        if (have_se) var[c] += double(render_se.at(x, y)[c]) * render_se.at(x, y)[c];
                    }
                    ++count;
                }
            if (!count) continue;
            ++out.blocks;
            out.pixels_compared += count;
            for (int c = 0; c < 3; ++c) {
                const double m = mine[c] / count, t = theirs[c] / count;
                const double d = encode_levels(m) - encode_levels(t);
                sum_abs += std::abs(d);
                sum_signed += d;
                out.max_abs_diff = std::max(out.max_abs_diff, std::abs(d));
                ++terms;
                reference_sum += t;
                if (have_se) block_errors.push_back({std::abs(d), se_levels(m, t, std::sqrt(var[c]) / count), t});
            }
        }
    if (have_se && !block_errors.empty()) {
        out.block_channels = int(block_errors.size());
        out.z_limit = normal_quantile_two_sided(1e-3 / double(block_errors.size()));
        double noise = 0;
        for (const BlockError& b : block_errors) noise += b.se;
        out.mean_noise_levels = std::sqrt(2.0 / M_PI) * noise / double(block_errors.size());
        const double negligible = kUnresolvedNegligibleFraction * reference_sum / double(block_errors.size());
        for (const BlockError& b : block_errors) {
            const double excess = b.abs_diff - 1.0;
            if (excess <= 0) continue;
            const double z = b.se > 0 ? excess / b.se : INFINITY;
            out.worst_excess = std::max(out.worst_excess, z);
            if (z > out.z_limit) ++out.blocks_beyond_noise;
            if (!(b.se > 0) && b.reference < negligible) ++out.unresolved_block_channels;
        }
    }
    if (terms) {
        out.mean_abs_diff = sum_abs / double(terms);
        out.mean_signed_diff = sum_signed / double(terms);
    }
    return out;
}

}  // namespace pathlab
