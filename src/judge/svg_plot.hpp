// A log-log line plot as a self-contained SVG (no fonts or scripts fetched): decade grid
// lines and labels, one polyline with markers per series, a legend, and optionally a dashed
// guide of slope -1/2 (the Monte Carlo rate, error ~ time^-1/2).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace pathlab {

struct PlotSeries {
    std::string label;
    std::string colour;  // CSS colour
    std::vector<std::pair<double, double>> points;  // (x, y); points with x <= 0 or y <= 0 are skipped
};

struct LogLogPlot {
    std::string title, x_label, y_label;
    int width = 640, height = 400;
    bool slope_guide = true;
};

std::string log_log_svg(const LogLogPlot& plot, const std::vector<PlotSeries>& series);

// A colour-blind-safe palette (Okabe & Ito), cycled.
std::string series_colour(size_t index);

// Text for HTML/SVG content and attribute values (& < > " ').
std::string xml_escape(const std::string& text);

}  // namespace pathlab
