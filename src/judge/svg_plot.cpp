#include "judge/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>

namespace pathlab {
namespace {

bool usable(const std::pair<double, double>& p) {
    return p.first > 0 && p.second > 0 && std::isfinite(p.first) && std::isfinite(p.second);
}

// A decade's value as short text: 0.001, 0.01, ..., 1, 10, 100, 1e+04.
std::string decade_label(int k) { return std::abs(k) <= 3 ? fmt::format("{}", std::pow(10.0, k)) : fmt::format("1e{:+03d}", k); }

// m x 10^k as short text (2, 50, 0.005, 2e+05).
struct Range {
    double lo, hi;
};

// The largest of 1, 2, 5 x 10^k at most lo and the smallest at least hi, widened (by 1-2-5
// steps, alternately) until they span at least a decade.
Range nice_range(double lo, double hi) {
    constexpr double eps = 1e-9;
    const auto decade = [](double v) { return std::pow(10.0, std::floor(std::log10(v) + eps)); };
    const auto nice_floor = [&](double v) {
        const double k = decade(v), m = v / k;
        return (m >= 5 - eps ? 5 : m >= 2 - eps ? 2 : 1) * k;
    };
    const auto nice_ceil = [&](double v) {
        const double k = decade(v), m = v / k;
        return (m <= 1 + eps ? 1 : m <= 2 + eps ? 2 : m <= 5 + eps ? 5 : 10) * k;
    };
    // The next 1-2-5 value below and above a 1-2-5 value.
    const auto below = [&](double v) {
        const double k = decade(v), m = std::round(v / k);
        return m >= 5 ? 2 * k : m >= 2 ? k : 0.5 * k;
    };
    const auto above = [&](double v) {
        const double k = decade(v), m = std::round(v / k);
        return m >= 5 ? 10 * k : m >= 2 ? 5 * k : 2 * k;
    };
    Range r{nice_floor(lo), nice_ceil(hi)};
    for (int i = 0; r.hi / r.lo < 10 - 1e-6 && i < 12; ++i) (i % 2 ? r.lo = below(r.lo) : r.hi = above(r.hi));
    return r;
}

std::string minor_label(int m, int k) { return std::abs(k) <= 3 ? fmt::format("{:g}", m * std::pow(10.0, k)) : fmt::format("{}e{:+03d}", m, k); }

}  // namespace

std::string series_colour(size_t index) {
    static const char* const palette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442"};
    return palette[index % std::size(palette)];
}

std::string xml_escape(const std::string& text) {
    std::string out;
    for (const char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string log_log_svg(const LogLogPlot& plot, const std::vector<PlotSeries>& series) {
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (const PlotSeries& s : series)
        for (const auto& p : s.points)
            if (usable(p)) {
                x0 = std::min(x0, p.first), x1 = std::max(x1, p.first);
                y0 = std::min(y0, p.second), y1 = std::max(y1, p.second);
            }
    if (!(x0 <= x1)) x0 = 0.1, x1 = 10, y0 = 0.01, y1 = 1;  // nothing to plot: an empty frame
    // Axes from the 1-2-5 values around the data (at least a decade each), so the curves fill the plot.
    const Range xr = nice_range(x0, x1), yr = nice_range(y0, y1);
    const double lx0 = std::log10(xr.lo), lx1 = std::log10(xr.hi), ly0 = std::log10(yr.lo), ly1 = std::log10(yr.hi);
    const int dx0 = int(std::floor(lx0)), dx1 = int(std::ceil(lx1)), dy0 = int(std::floor(ly0)), dy1 = int(std::ceil(ly1));

    const double left = 70, right = 170, top = 36, bottom = 50;
    const double pw = plot.width - left - right, ph = plot.height - top - bottom;
    const auto X = [&](double x) { return left + pw * (std::log10(x) - lx0) / (lx1 - lx0); };
    const auto Y = [&](double y) { return top + ph * (1.0 - (std::log10(y) - ly0) / (ly1 - ly0)); };

    std::string svg = fmt::format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
        "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n",
        plot.width, plot.height);
    svg += fmt::format("<text x=\"{}\" y=\"20\" font-size=\"14\" text-anchor=\"middle\">{}</text>\n", left + pw / 2, xml_escape(plot.title));
    // Grid: m x 10^k inside the range; decades labelled, and 2 and 5 when the range is short.
    const auto inside = [](double v, const Range& r) { return v >= r.lo * (1 - 1e-9) && v <= r.hi * (1 + 1e-9); };
    for (int k = dx0; k <= dx1; ++k)
        for (int m = 1; m <= 9; ++m) {
            const double v = m * std::pow(10.0, k);
            if (!inside(v, xr)) continue;
            svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"{3}\"/>\n", X(v), top, top + ph,
                               m == 1 ? "#bbb" : "#eee");
            if (m == 1 || ((m == 2 || m == 5) && lx1 - lx0 <= 2.01))
                svg += fmt::format("<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\"{}>{}</text>\n", X(v), top + ph + 18,
                                   m == 1 ? "" : " fill=\"#666\"", m == 1 ? decade_label(k) : minor_label(m, k));
        }
    for (int k = dy0; k <= dy1; ++k)
        for (int m = 1; m <= 9; ++m) {
            const double v = m * std::pow(10.0, k);
            if (!inside(v, yr)) continue;
            svg += fmt::format("<line x1=\"{1}\" y1=\"{0:.1f}\" x2=\"{2}\" y2=\"{0:.1f}\" stroke=\"{3}\"/>\n", Y(v), left, left + pw,
                               m == 1 ? "#bbb" : "#eee");
            if (m == 1 || ((m == 2 || m == 5) && ly1 - ly0 <= 2.01))
                svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\"{}>{}</text>\n", left - 6, Y(v) + 4,
                                   m == 1 ? "" : " fill=\"#666\"", m == 1 ? decade_label(k) : minor_label(m, k));
        }
    svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\"/>\n", left, top, pw, ph);
    svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", left + pw / 2, plot.height - 10, xml_escape(plot.x_label));
    svg += fmt::format("<text transform=\"translate(16 {}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n", top + ph / 2,
                       xml_escape(plot.y_label));

    // An id of its own, so that several plots can share a page.
    const std::string clip = fmt::format("plot-area-{:016x}", std::hash<std::string>{}(plot.title + plot.x_label + plot.y_label));
    svg += fmt::format("<clipPath id=\"{0}\"><rect x=\"{1}\" y=\"{2}\" width=\"{3}\" height=\"{4}\"/></clipPath>\n"
                       "<g clip-path=\"url(#{0})\">\n", clip, left, top, pw, ph);
    for (size_t i = 0; i < series.size(); ++i) {
        const PlotSeries& s = series[i];
        std::string pts;
        for (const auto& p : s.points)
            if (usable(p)) pts += fmt::format("{:.1f},{:.1f} ", X(p.first), Y(p.second));
        if (pts.empty()) continue;
        svg += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"2\" points=\"{}\"/>\n", s.colour, pts);
        for (const auto& p : s.points)
            if (usable(p)) svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" fill=\"{}\"/>\n", X(p.first), Y(p.second), s.colour);
    }
    // The -1/2 guide, over half the plot's width (at most a decade), where it and its label are
    // farthest from every curve: candidates on a grid over the plot area, scored in pixels.
    if (plot.slope_guide) {
        std::vector<std::pair<double, double>> curve;  // screen points of every curve, segments densified
        for (const PlotSeries& s : series) {
            std::vector<std::pair<double, double>> pts;
            for (const auto& p : s.points)
                if (usable(p)) pts.push_back({X(p.first), Y(p.second)});
            for (size_t k = 0; k < pts.size(); ++k) {
                curve.push_back(pts[k]);
                if (k + 1 == pts.size()) break;
                const double len = std::hypot(pts[k + 1].first - pts[k].first, pts[k + 1].second - pts[k].second);
                for (int t = 1; t < int(len / 4); ++t) {
                    const double f = t * 4.0 / len;
                    curve.push_back({pts[k].first + f * (pts[k + 1].first - pts[k].first), pts[k].second + f * (pts[k + 1].second - pts[k].second)});
                }
            }
        }
        const double span = std::min(0.5 * pw, pw / (lx1 - lx0));     // one decade, or half the width
        const double rise = 0.5 * span * ph / pw * (lx1 - lx0) / (ly1 - ly0);  // slope -1/2 in screen units
        const double label_w = 70, label_h = 14;
        double best_score = -1, bx = left + 10, by = top + 10;
        for (double gx = left + 8; gx + span + 8 <= left + pw; gx += pw / 24)
            for (double gy = top + label_h + 8; gy + rise + 8 <= top + ph; gy += ph / 24) {
                // Segment from (gx, gy) to (gx + span, gy + rise); label above its left end.
                double score = 1e9;
                for (const auto& c : curve) {
                    for (int t = 0; t <= 8; ++t) {
                        const double sx = gx + span * t / 8.0, sy = gy + rise * t / 8.0;
                        score = std::min(score, std::hypot(c.first - sx, c.second - sy));
                    }
                    const double lx = std::clamp(c.first, gx, gx + label_w), ly = std::clamp(c.second, gy - label_h - 4, gy - 4);
                    score = std::min(score, std::hypot(c.first - lx, c.second - ly));
                }
                if (score > best_score) best_score = score, bx = gx, by = gy;
            }
        svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#666\" stroke-dasharray=\"5 4\"/>\n", bx, by,
                           bx + span, by + rise);
        svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" fill=\"#666\">slope -1/2</text>\n", bx, by - 6);
    }
    svg += "</g>\n";
    // Legend.
    for (size_t i = 0; i < series.size(); ++i) {
        const double y = top + 10 + 20.0 * double(i);
        svg += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"{3}\" stroke-width=\"2\"/>"
                           "<text x=\"{4}\" y=\"{5}\">{6}</text>\n",
                           left + pw + 12, y, left + pw + 34, series[i].colour, left + pw + 40, y + 4, xml_escape(series[i].label));
    }
    svg += "</svg>\n";
    return svg;
}

}  // namespace pathlab
