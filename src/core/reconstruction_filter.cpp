#include "core/reconstruction_filter.hpp"

#include <fmt/format.h>

namespace pathlab {

std::vector<PluginInfo> rfilter_plugins() {
    static const std::vector<PluginInfo> plugins = {
        {"rfilter", "box", "1 within radius of the pixel centre: with the default radius 0.5, pathlab's film (each sample in its own pixel)",
         {{"radius", ParamType::Float, "0.5", "half width in pixels (above 0.5 a sample reaches neighbouring pixels)"}}},
        {"rfilter", "tent", "max(0, 1 - |x| / radius): a triangle, separable in x and y",
         {{"radius", ParamType::Float, "1", "half width in pixels"}}},
        {"rfilter", "gaussian", "exp(-x^2 / (2 stddev^2)) minus its value at 4 stddev, cut there (Mitsuba's default filter)",
         {{"stddev", ParamType::Float, "0.5", "standard deviation in pixels (the radius is 4 stddev)"}}},
        {"rfilter", "mitchell", "Mitchell-Netravali cubic, radius 2 (negative lobes)",
         {{"B", ParamType::Float, "0.333333", "B of the paper"}, {"C", ParamType::Float, "0.333333", "C of the paper"}}},
        {"rfilter", "catmullrom", "Catmull-Rom cubic (Mitchell-Netravali with B = 0, C = 1/2), radius 2", {}},
        {"rfilter", "lanczos", "sinc(x) sinc(x / lobes), radius = lobes (negative lobes, rings at edges)",
         {{"lobes", ParamType::Integer, "3", "number of lobes, 1 to 8"}}},
    };
    return plugins;
}

FilterDesc read_rfilter(Properties& p) {
    FilterDesc f;
    f.type = p.plugin().type;
    if (f.type == "box" || f.type == "tent") {
        f.radius = p.get_float("radius");
        if (!(f.radius >= 0.5 && f.radius <= 8))
            p.fail("radius", fmt::format("a {} filter's radius must be 0.5 to 8 pixels, got {}", f.type, f.radius));
    } else if (f.type == "gaussian") {
        f.stddev = p.get_float("stddev");
        if (!(f.stddev >= 0.125 && f.stddev <= 2)) p.fail("stddev", fmt::format("stddev must be 0.125 to 2 pixels, got {}", f.stddev));
        f.radius = 4 * f.stddev;
    } else if (f.type == "mitchell" || f.type == "catmullrom") {
        f.radius = 2;
        if (f.type == "catmullrom") {
            f.b = 0, f.c = 0.5;
        } else {
            f.b = p.get_float("B"), f.c = p.get_float("C");
            if (!(std::abs(f.b) <= 10 && std::abs(f.c) <= 10)) p.fail("B and C must be at most 10 in magnitude");
        }
    } else if (f.type == "lanczos") {
        const int lobes = p.get_int("lobes");
        if (lobes < 1 || lobes > 8) p.fail("lobes", fmt::format("lobes must be 1 to 8, got {}", lobes));
        f.radius = lobes;
    }
    return f;
}

}  // namespace pathlab
