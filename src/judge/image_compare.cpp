#include "judge/image_compare.hpp"

#include <cmath>
#include <stdexcept>
#include <limits>

#include <fmt/format.h>

namespace pathlab {
namespace {

struct Accumulator {
    double sum = 0, sum_abs = 0, sum_sq = 0, sum_rel = 0, max_abs = 0;
    long n = 0;
    void add(double a, double b) {
        const double d = a - b;
        sum += d;
        sum_abs += std::abs(d);
        sum_sq += d * d;
        sum_rel += d * d / (b * b + kRelMseEpsilon);
        max_abs = std::max(max_abs, std::abs(d));
        ++n;
    }
    void merge(const Accumulator& o) {
        sum += o.sum, sum_abs += o.sum_abs, sum_sq += o.sum_sq, sum_rel += o.sum_rel, n += o.n;
        max_abs = std::max(max_abs, o.max_abs);
    }
    ChannelStatistics statistics() const {
        // Nothing compared (every pair had a NaN or an infinity): no statistic, not a perfect 0.
        if (n == 0) {
            const double nan = std::numeric_limits<double>::quiet_NaN();
            return {nan, nan, nan, nan, nan};
        }
        const double dn = double(n);
        return {sum / dn, sum_abs / dn, std::sqrt(sum_sq / dn), sum_rel / dn, max_abs};
    }
};

void count_non_finite(float v, long& nan, long& inf) {
    if (std::isnan(v)) ++nan;
    else if (std::isinf(v)) ++inf;
}

}  // namespace

double ImageDifference::worst_mean_diff() const {
    double worst = 0;
    for (const ChannelStatistics& c : channel) worst = std::max(worst, std::abs(c.mean_diff));
    return worst;
}

ImageDifference compare_images(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height())
        throw ImageSizeMismatch(fmt::format("images differ in size: {}x{} and {}x{}", a.width(), a.height(), b.width(), b.height()));
    ImageDifference out;
    out.width = a.width();
    out.height = a.height();
    Accumulator acc[3];
    for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float va = a[i][c], vb = b[i][c];
            count_non_finite(va, out.nan_a, out.inf_a);
            count_non_finite(vb, out.nan_b, out.inf_b);
            if (std::isfinite(va) && std::isfinite(vb)) acc[c].add(va, vb);
        }
    Accumulator total;
    for (int c = 0; c < 3; ++c) {
        out.channel[size_t(c)] = acc[c].statistics();
        total.merge(acc[c]);
    }
    out.all = total.statistics();
    out.compared = total.n;
    return out;
}

bool image_metric(const ImageDifference& d, const std::string& name, double& value) {
    if (name == "mean") value = d.worst_mean_diff();
    else if (name == "mae") value = d.all.mae;
    else if (name == "rmse") value = d.all.rmse;
    else if (name == "relmse") value = d.all.relmse;
    else if (name == "max") value = d.all.max_abs_diff;
    else return false;
    return true;
}

}  // namespace pathlab

namespace pathlab {

double rmse_against_reference(const Image& image, const Image& reference, const Image& reference_se) {
    if (image.width() != reference.width() || image.height() != reference.height())
        throw ImageSizeMismatch(fmt::format("images differ in size: {}x{} and {}x{}", image.width(), image.height(),
                                            reference.width(), reference.height()));
    if (reference_se.pixel_count() != 0 && (reference_se.width() != reference.width() || reference_se.height() != reference.height()))
        throw ImageSizeMismatch(fmt::format("the reference's standard errors are {}x{}, the reference {}x{}", reference_se.width(),
                                            reference_se.height(), reference.width(), reference.height()));
    const bool noisy = reference_se.pixel_count() == reference.pixel_count();
    double sum_sq = 0, noise = 0;
    long n = 0;
    for (size_t i = 0; i < image.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double a = image[i][c], b = reference[i][c];
            if (!std::isfinite(a) || !std::isfinite(b)) continue;
            sum_sq += (a - b) * (a - b);
            if (noisy) {
                // A NaN or negative standard error is no standard error (a NaN made the result 0).
                const double se = reference_se[i][c];
                if (!(se >= 0) || !std::isfinite(se))
                    throw std::invalid_argument(fmt::format("the reference's standard error at pixel ({}, {}) is {}: standard errors are "
                                                            "finite and not negative",
                                                            i % size_t(reference.width()), i / size_t(reference.width()), se));
                noise += se * se;
            }
            ++n;
        }
    return n ? std::sqrt(std::max(0.0, (sum_sq - noise) / double(n))) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace pathlab
