#include "judge/svg_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace pathlab {
namespace {

bool usable(const std::pair<double, double>& p) {
    return p.first > 0 && p.second > 0 && std::isfinite(p.first) && std::isfinite(p.second);
}

// A decade's value as short text: 0.001, 0.01, ..., 1, 10, 100, 1e+04.
std::string decade_label(int k) { return std::abs(k) <= 3 ? fmt::format("{}", std::pow(10.0, k)) : fmt::format("1e{:+03d}", k); }

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
    // Whole decades around the data.
    const int dx0 = int(std::floor(std::log10(x0))), dx1 = std::max(dx0 + 1, int(std::ceil(std::log10(x1))));
    const int dy0 = int(std::floor(std::log10(y0))), dy1 = std::max(dy0 + 1, int(std::ceil(std::log10(y1))));

    const double left = 70, right = 170, top = 36, bottom = 50;
    const double pw = plot.width - left - right, ph = plot.height - top - bottom;
    const auto X = [&](double x) { return left + pw * (std::log10(x) - dx0) / (dx1 - dx0); };
    const auto Y = [&](double y) { return top + ph * (1.0 - (std::log10(y) - dy0) / (dy1 - dy0)); };

    std::string svg = fmt::format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
        "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n",
        plot.width, plot.height);
    svg += fmt::format("<text x=\"{}\" y=\"20\" font-size=\"14\" text-anchor=\"middle\">{}</text>\n", left + pw / 2, xml_escape(plot.title));
    // Grid: decades (labelled) and 2..9 within them.
    for (int k = dx0; k <= dx1; ++k) {
        for (int m = 1; m <= 9 && (m == 1 || k < dx1); ++m) {
            const double x = X(m * std::pow(10.0, k));
            svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"{3}\"/>\n", x, top, top + ph,
                               m == 1 ? "#bbb" : "#eee");
        }
        svg += fmt::format("<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", X(std::pow(10.0, k)), top + ph + 18, decade_label(k));
    }
    for (int k = dy0; k <= dy1; ++k) {
        for (int m = 1; m <= 9 && (m == 1 || k < dy1); ++m) {
            const double y = Y(m * std::pow(10.0, k));
            svg += fmt::format("<line x1=\"{1}\" y1=\"{0:.1f}\" x2=\"{2}\" y2=\"{0:.1f}\" stroke=\"{3}\"/>\n", y, left, left + pw,
                               m == 1 ? "#bbb" : "#eee");
        }
        svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", left - 6, Y(std::pow(10.0, k)) + 4, decade_label(k));
    }
    svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\"/>\n", left, top, pw, ph);
    svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", left + pw / 2, plot.height - 10, xml_escape(plot.x_label));
    svg += fmt::format("<text transform=\"translate(16 {}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n", top + ph / 2,
                       xml_escape(plot.y_label));

    svg += fmt::format("<clipPath id=\"plot-area\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n"
                       "<g clip-path=\"url(#plot-area)\">\n", left, top, pw, ph);
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
    // The -1/2 guide through the last point of the first series that has one, over one decade.
    if (plot.slope_guide)
        for (const PlotSeries& s : series) {
            auto last = std::find_if(s.points.rbegin(), s.points.rend(), usable);
            if (last == s.points.rend()) continue;
            const double xa = std::max(last->first / 10.0, std::pow(10.0, dx0));
            const double ya = last->second * std::sqrt(last->first / xa);
            svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#666\" stroke-dasharray=\"5 4\"/>\n",
                               X(xa), Y(ya), X(last->first), Y(last->second));
            svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" fill=\"#666\">slope -1/2</text>\n", X(xa) + 4, Y(ya) - 6);
            break;
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
