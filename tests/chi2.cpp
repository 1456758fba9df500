#include "chi2.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

namespace pathlab::test {
namespace {

// Regularised lower incomplete gamma P(a, x) by its series, and upper Q(a, x) by Lentz's
// continued fraction (Numerical Recipes, 6.2).
double gamma_p_series(double a, double x) {
    double sum = 1.0 / a, term = sum;
    for (int n = 1; n < 10000; ++n) {
        term *= x / (a + n);
        sum += term;
        if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

double gamma_q_fraction(double a, double x) {
    const double tiny = 1e-300;
    double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        const double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1 / d;
        const double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1) < 1e-15) break;
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace

double chi2_survival(double x, int dof) {
    if (x <= 0) return 1;
    const double a = 0.5 * dof, hx = 0.5 * x;
    return hx < a + 1 ? 1 - gamma_p_series(a, hx) : gamma_q_fraction(a, hx);
}

double sidak_alpha(int tests, double family_alpha) { return 1 - std::pow(1 - family_alpha, 1.0 / tests); }

std::string Chi2Result::describe() const {
    return fmt::format("chi2 = {:.1f}, dof = {}, p = {:.3g}, pdf integral = {:.5f}, rejected = {:.5f}, "
                       "samples in cells of zero pdf = {}",
                       statistic, dof, p_value, pdf_integral, rejected_fraction, zero_pdf_samples);
}

Chi2Result chi2_from_counts(const std::vector<double>& observed, const std::vector<double>& expected) {
    // The last cell holds rejections (see chi2_directions); it is not a cell of zero pdf.
    Chi2Result r;
    // Pool cells with expected counts below 5 (chi-square needs reasonably large counts).
    std::vector<size_t> order(observed.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    double pooled_e = 0, pooled_o = 0, stat = 0;
    int cells = 0;
    for (size_t i : order) {
        if (expected[i] == 0 && i + 1 < observed.size()) r.zero_pdf_samples += observed[i];
        if (expected[i] < 5) {
            pooled_e += expected[i];
            pooled_o += observed[i];
            if (pooled_e >= 5) {
                stat += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
                ++cells;
                pooled_e = pooled_o = 0;
            }
            continue;
        }
        stat += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
        ++cells;
    }
    if (pooled_e > 0) {
        stat += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        ++cells;
    }
    r.statistic = stat;
    r.dof = std::max(1, cells - 1);
    r.p_value = chi2_survival(stat, r.dof);
    return r;
}

Chi2Result chi2_directions(const DirectionSampler& sample, const DirectionPdf& pdf, const Vec3f& axis,
                           const Chi2Options& o) {
    const Frame frame(normalize(axis));
    const int nt = o.theta_bins, np = o.phi_bins;
    std::vector<double> edges(size_t(nt) + 1);
    for (int k = 0; k <= nt; ++k) edges[size_t(k)] = kPi * std::pow(double(k) / nt, o.theta_power);
    const auto theta_bin = [&](double theta) {
        const int k = int(std::upper_bound(edges.begin(), edges.end(), theta) - edges.begin()) - 1;
        return std::clamp(k, 0, nt - 1);
    };

    // Observed counts.
    std::vector<double> observed(size_t(nt) * size_t(np) + 1, 0.0);  // last cell: rejections
    Sampler rng(o.seed, 0, 0);
    Chi2Result r;
    for (int i = 0; i < o.samples; ++i) {
        const auto w = sample(rng.next2d());
        if (!w) {
            observed.back() += 1;
            continue;
        }
        const Vec3f l = frame.to_local(normalize(*w));
        // atan2 keeps precision near the pole, where acos of a float z cannot resolve
        // angles below ~5e-4 rad.
        const double theta = std::atan2(std::hypot(double(l.x), double(l.y)), double(l.z));
        double phi = std::atan2(double(l.y), double(l.x));
        if (phi < 0) phi += 2 * M_PI;
        const int p = std::min(int(phi / (2 * M_PI) * np), np - 1);
        observed[size_t(theta_bin(theta)) * size_t(np) + size_t(p)] += 1;
    }

    // Expected counts: composite midpoint rule over each cell of pdf * sin(theta) d theta d phi.
    // Interior points only, so a pdf that jumps on a cell edge (the horizon) is integrated
    // without bias from evaluating it exactly at the jump.
    std::vector<double> expected(observed.size(), 0.0);
    const int m = o.integration_steps;
    double total = 0;
    for (int t = 0; t < nt; ++t) {
        const double t0 = edges[size_t(t)], t1 = edges[size_t(t) + 1];
        for (int p = 0; p < np; ++p) {
            const double p0 = 2 * M_PI * p / np, p1 = 2 * M_PI * (p + 1) / np;
            double sum = 0;
            for (int i = 0; i < m; ++i) {
                const double theta = t0 + (t1 - t0) * (i + 0.5) / m;
                const double st = std::sin(theta), ct = std::cos(theta);
                for (int j = 0; j < m; ++j) {
                    const double phi = p0 + (p1 - p0) * (j + 0.5) / m;
                    const Vec3f local(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
                    sum += double(pdf(frame.to_world(local))) * st;
                }
            }
            const double integral = sum * (t1 - t0) * (p1 - p0) / (double(m) * m);
            expected[size_t(t) * size_t(np) + size_t(p)] = integral * o.samples;
            total += integral;
        }
    }
    expected.back() = std::max(0.0, 1 - total) * o.samples;
    r.pdf_integral = total;
    r.rejected_fraction = observed.back() / o.samples;

    const Chi2Result counts = chi2_from_counts(observed, expected);
    r.statistic = counts.statistic;
    r.dof = counts.dof;
    r.p_value = counts.p_value;
    r.zero_pdf_samples = counts.zero_pdf_samples;
    return r;
}

}  // namespace pathlab::test
