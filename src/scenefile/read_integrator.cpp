// <integrator type>: any pathlab integrator by name or alias (Mitsuba's path, direct and
// ptracer among them), with its declared parameters.
#include <fmt/format.h>

#include "integrators/integrator.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {

void read_integrator(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type"});
    if (b.have_integrator) xml.fail(n, "a scene can have only one <integrator>");
    b.have_integrator = true;
    const std::string type = xml.attr(n, "type");
    const IntegratorInfo* info = find_integrator(type);
    if (!info) xml.fail(n, fmt::format("unsupported integrator type '{}'; supported: {}", type, integrator_names()));
    b.desc.algorithm = info->name;
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "an <integrator> has no nested plugins");
    const PluginInfo plugin = info->plugin();
    Properties p = xml.properties(n, plugin);
    reading([&] {
        // Mitsuba counts path segments (1: emitters only, 2: direct light); pathlab counts bounces.
        if (plugin.find("max_depth") && p.has("max_depth")) {
            const int depth = p.get_int("max_depth");
            if (depth == -1) b.desc.max_depth = -1;
            else if (depth >= 2) b.desc.max_depth = depth - 1;
            else p.fail("max_depth", fmt::format("max_depth must be -1 (unlimited) or at least 2 (pathlab needs one bounce), got {}", depth));
        }
        if (plugin.find("rr_depth") && p.has("rr_depth")) {
            const int depth = p.get_int("rr_depth");
            if (depth < 1) p.fail("rr_depth", fmt::format("rr_depth must be at least 1, got {}", depth));
            b.desc.rr_depth = depth - 1;
        }
        // Photon mapping (Mitsuba 0.6's sppm spells them photonCount, initialRadius, alpha).
        if (plugin.find("photon_count") && p.has("photon_count")) {
            const int n = p.get_int("photon_count");
            if (n < 0) p.fail("photon_count", fmt::format("photon_count must be zero (the default) or positive, got {}", n));
            b.desc.photons = n;
        }
        if (plugin.find("initial_radius") && p.has("initial_radius")) {
            const float r = p.get_float("initial_radius");
            if (!(r >= 0) || !std::isfinite(r))
                p.fail("initial_radius", fmt::format("initial_radius must be zero (from the scene's size) or positive, got {}", r));
            b.desc.photon_radius = r;
        }
        if (plugin.find("alpha") && p.has("alpha")) {
            const float a = p.get_float("alpha");
            if (!(a > 0 && a <= 1)) p.fail("alpha", fmt::format("alpha must be in (0, 1], got {}", a));
            b.desc.photon_alpha = a;
        }
        p.check_all_used();
        return 0;
    });
}

}  // namespace pathlab
