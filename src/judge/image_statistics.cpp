#include "judge/image_statistics.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace pathlab {

double normal_quantile_two_sided(double alpha) {
    // Bisection on erfc: P(|Z| > z) = erfc(z / sqrt 2).
    double lo = 0, hi = 40;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (std::erfc(mid / std::sqrt(2.0)) > alpha ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

long binomial_upper_quantile(long n, double p, double alpha) {
    // Accumulate the pmf in log space until the upper tail is below alpha.
    double cdf = 0;
    for (long k = 0; k <= n; ++k) {
        const double log_pmf = std::lgamma(double(n) + 1) - std::lgamma(double(k) + 1) - std::lgamma(double(n - k) + 1) +
                               double(k) * std::log(p) + double(n - k) * std::log1p(-p);
        cdf += std::exp(log_pmf);
        if (1 - cdf <= alpha) return k;
    }
    return n;
}

std::string AgreementResult::describe() const {
    return fmt::format("{}: {} outliers (allowed {}) of {} pixel-channels, max |z| = {:.2f}, bias z = ({:.2f}, {:.2f}, "
                       "{:.2f}) (limit {:.2f}), {} unresolved{}",
                       agree ? "agree" : "DISAGREE", outliers, allowed_outliers, pixels, max_abs_z, bias_z[0], bias_z[1],
                       bias_z[2], bias_limit, unresolved, excluded ? fmt::format(", {} pixels left out", excluded) : "");
}

AgreementResult test_agreement(const Image& a, const Image& se_a, const Image& b, const Image& se_b,
                               const AgreementOptions& o) {
    const bool b_exact = se_b.pixel_count() == 0;
    if (a.width() != b.width() || a.height() != b.height() || se_a.pixel_count() != a.pixel_count() ||
        (!b_exact && se_b.pixel_count() != b.pixel_count()))
        throw std::invalid_argument("test_agreement: images differ in size");
    AgreementResult r;
    const double channel_pixel_alpha = o.pixel_alpha;
    const double channel_family_alpha = o.family_alpha / 6;  // 3 channels x 2 checks
    const double z_pixel = normal_quantile_two_sided(channel_pixel_alpha);
    if (o.excluded && o.excluded->size() != a.pixel_count()) throw std::invalid_argument("test_agreement: the mask differs in size");
    const auto left_out = [&](size_t i) { return o.excluded && (*o.excluded)[i] != 0; };
    for (size_t i = 0; i < a.pixel_count(); ++i) r.excluded += left_out(i);
    const long n = long(a.pixel_count()) - r.excluded;
    r.pixels = 3 * n;
    r.allowed_outliers = binomial_upper_quantile(n, channel_pixel_alpha, channel_family_alpha);
    r.bias_limit = normal_quantile_two_sided(channel_family_alpha);
    for (int c = 0; c < 3; ++c) {
        double mean_b = 0;
        for (size_t i = 0; i < b.pixel_count(); ++i) mean_b += std::abs(double(b[i][c]));
        mean_b /= double(std::max<size_t>(1, b.pixel_count()));
        long outliers = 0;
        double sum_d = 0, sum_var = 0;
        for (size_t i = 0; i < a.pixel_count(); ++i) {
            if (left_out(i)) continue;
            // Images are stored in float: differences at rounding level are no difference (a
            // zero-variance estimator, such as BRDF sampling in a white furnace, would otherwise
            // meet a standard error of 0 with a rounding error).
            double d = double(a[i][c]) - double(b[i][c]);
            if (std::abs(d) <= 1e-6 * std::max(std::abs(double(a[i][c])), std::abs(double(b[i][c])))) d = 0;
            const double sb = b_exact ? 0.0 : double(se_b[i][c]);
            const double se = std::sqrt(double(se_a[i][c]) * se_a[i][c] + sb * sb);
            // One image has no variance here. If its value is not 0, every one of its samples
            // gave that value (an emitter seen directly): it is exact, and the z of the other
            // image's error decides. If it is 0, it may simply have drawn no hit yet.
            const bool a_flat = se_a[i][c] == 0, b_flat = !b_exact && sb == 0;
            const bool flat_is_exact = (a_flat && a[i][c] != 0) || (b_flat && b[i][c] != 0);
            if (!b_exact && a_flat != b_flat && d != 0 && !flat_is_exact) {
                if (std::abs(d) <= o.negligible_fraction * mean_b) {
                    ++r.unresolved;
                    continue;
                }
                ++outliers;
                r.max_abs_z = INFINITY;
                continue;
            }
            double z = 0;
            if (se > 0) z = d / se;
            else if (d != 0) z = INFINITY;
            if (std::abs(z) > z_pixel) ++outliers;
            sum_d += d, sum_var += se * se;
            r.max_abs_z = std::max(r.max_abs_z, std::abs(z));
        }
        r.bias_z[c] = sum_var > 0 ? sum_d / std::sqrt(sum_var) : (sum_d == 0 ? 0.0 : INFINITY);
        r.outliers = std::max(r.outliers, outliers);
        if (outliers > r.allowed_outliers || std::abs(r.bias_z[c]) > r.bias_limit) r.agree = false;
    }
    if (double(r.unresolved) > o.max_unresolved_fraction * double(r.pixels)) r.agree = false;
    return r;
}

}  // namespace pathlab
