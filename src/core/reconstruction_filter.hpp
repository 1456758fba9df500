// Reconstruction filters (Mitsuba's <rfilter>): separable pixel filters, f(dx) f(dy), with
// Mitsuba's footprints and defaults. Each declares its parameters next to its formula; the
// film's pass machinery (render/pixel_filter.hpp) spreads samples with them.
//   box         1 for |x| <= radius                                   radius 0.5 (pathlab's film: one pixel)
//   tent        max(0, 1 - |x| / radius)                              radius 1
//   gaussian    max(0, exp(-x^2 / (2 s^2)) - exp(-r^2 / (2 s^2))), r = 4 s    stddev s = 0.5
//   mitchell    Mitchell-Netravali cubic (B, C), radius 2             B = C = 1/3
//   catmullrom  the cubic with B = 0, C = 1/2, radius 2
//   lanczos     sinc(x) sinc(x / lobes), radius = lobes               lobes 3
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/properties.hpp"

namespace pathlab {

struct FilterDesc {
    std::string type = "box";
    double radius = 0.5;  // half width in pixels: f(x) = 0 for |x| > radius
    double stddev = 0.5;  // gaussian
    double b = 1.0 / 3, c = 1.0 / 3;  // mitchell, catmullrom

    bool is_box() const { return type == "box"; }
    // The 1D filter at x pixels from the pixel's centre.
    double eval(double x) const {
        x = std::abs(x);
        if (x > radius) return 0;
        if (type == "box") return 1;
        if (type == "tent") return 1 - x / radius;
        if (type == "gaussian") {
            const double alpha = -1 / (2 * stddev * stddev);
            return std::max(0.0, std::exp(alpha * x * x) - std::exp(alpha * radius * radius));
        }
        if (type == "lanczos") {
            if (x < 1e-7) return 1;
            const double x1 = 3.14159265358979323846 * x, x2 = x1 / radius;
            return std::sin(x1) * std::sin(x2) / (x1 * x2);
        }
        // mitchell, catmullrom
        const double x2 = x * x, x3 = x2 * x;
        if (x < 1) return ((12 - 9 * b - 6 * c) * x3 + (-18 + 12 * b + 6 * c) * x2 + (6 - 2 * b)) / 6;
        if (x < 2) return ((-b - 6 * c) * x3 + (6 * b + 30 * c) * x2 + (-12 * b - 48 * c) * x + (8 * b + 24 * c)) / 6;
        return 0;
    }
};

// The <rfilter> plugins (their PluginInfo, kind "rfilter").
std::vector<PluginInfo> rfilter_plugins();
// Reads an <rfilter type> from its properties (PropertyError for an invalid value).
FilterDesc read_rfilter(Properties& p);

}  // namespace pathlab
