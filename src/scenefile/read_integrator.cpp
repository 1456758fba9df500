// <integrator type>: any pathlab integrator by name or alias (Mitsuba's path, direct, ptracer,
// bdpt, sppm, ppm, photonmapper, irrcache among them), with its declared parameters; and
// Mitsuba's wrappers moment (the second moment beside the image) and aov (extra channels:
// depth, position, normals, albedo, uv) around one nested integrator.
#include <fmt/format.h>

#include "integrators/integrator.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

const PluginInfo& moment_plugin() {
    static const PluginInfo info{"integrator", "moment",
                                 "wraps one nested integrator; EXR outputs also get its second moment per pixel (channels m2.R, m2.G, m2.B) "
                                 "and the variance of the mean (var.R, var.G, var.B)",
                                 {}};
    return info;
}
const PluginInfo& aov_plugin() {
    static const PluginInfo info{"integrator", "aov",
                                 "extra EXR channels of the first surface seen (optionally around one nested integrator for the image)",
                                 {{"aovs", ParamType::String, "",
                                   "name:kind, ... with kinds depth, position, sh_normal, geo_normal, albedo, uv (e.g. \"dd.y:depth,nn:sh_normal\")"}}};
    return info;
}

const char* const kAovKinds[] = {"depth", "position", "sh_normal", "geo_normal", "albedo", "uv"};

void read_plain_integrator(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    const IntegratorInfo* info = find_integrator(type);
    if (!info) {
        // Not an error yet: -a may choose the estimator instead (the element is then skipped).
        const SourceLocation w = xml.where(n);
        b.desc.unknown_integrator = type;
        b.desc.unknown_integrator_at = fmt::format("{}:{}:{}", xml.file(), w.line, w.column);
        return;
    }
    b.desc.algorithm = info->name;
    // Mitsuba's volpath does not count a null BSDF sample (a straight pass) as a bounce; its path does.
    if (info->name == "volpath") b.desc.skip_null_events = true;
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
        if (plugin.find("hide_emitters") && p.has("hide_emitters")) b.desc.hide_emitters = p.get_bool("hide_emitters");
        if (plugin.find("samples_per_pass") && p.has("samples_per_pass")) {
            p.get_int("samples_per_pass");
            xml.note(n, "samples_per_pass is ignored: pathlab adds one sample per pixel per pass and stops on --spp or --time");
        }
        if (plugin.find("strict_normals") && p.has("strict_normals")) {
            p.get_bool("strict_normals");
            xml.note(n, "strict_normals is ignored: pathlab refuses light paths whose sides differ for the shading and geometric normal");
        }
        for (const char* count : {"shading_samples", "emitter_samples", "bsdf_samples"})
            if (plugin.find(count) && p.has(count) && p.get_int(count) != 1)
                p.fail(count, fmt::format("{} must be 1: pathlab's direct takes one light and one BSDF sample per pixel sample (raise "
                                          "the sample count instead), got {}", count, p.get_int(count)));
        // Photon mapping (Mitsuba 0.6's sppm spells them photonCount, initialRadius, alpha).
        if (plugin.find("photon_count") && p.has("photon_count")) {
            const int count = p.get_int("photon_count");
            if (count < 0) p.fail("photon_count", fmt::format("photon_count must be zero (the default) or positive, got {}", count));
            b.desc.photons = count;
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
        if (plugin.find("volume_estimate") && p.has("volume_estimate")) {
            const std::string v = p.get_string("volume_estimate");
            if (v != "beam" && v != "points") p.fail("volume_estimate", fmt::format("volume_estimate must be beam or points, got '{}'", v));
            b.desc.volume_beam = v == "beam";
        }
        // ic (Mitsuba 0.6's irrcache: resolution R means R x 3R rays; gradients, clampNeighbor and
        // clampScreen switch the same things; its quality, a weight of Tabellion and Lamorlette's
        // error with another radius, has no counterpart and is refused as unknown).
        if (plugin.find("rays") && p.has("rays")) {
            if (p.has("resolution")) p.fail("resolution", "give rays or resolution (Mitsuba's 3 R^2 rays), not both");
            const int n = p.get_int("rays");
            if (n < 4 || n > 65536) p.fail("rays", fmt::format("rays must be 4 to 65536, got {}", n));
            b.desc.ic_rays = n;
        }
        if (plugin.find("resolution") && p.has("resolution")) {
            const int r = p.get_int("resolution");
            if (r < 2 || r > 147) p.fail("resolution", fmt::format("resolution must be 2 to 147 (3 R^2 rays, at most 65536), got {}", r));
            b.desc.ic_rays = 3 * r * r;
        }
        if (plugin.find("error") && p.has("error")) {
            const float a = p.get_float("error");
            if (!(a >= 0 && a <= 10)) p.fail("error", fmt::format("error must be 0 to 10, got {}", a));
            b.desc.ic_error = a;
        }
        if (plugin.find("gradients") && p.has("gradients")) b.desc.ic_gradients = p.get_bool("gradients");
        if (plugin.find("clamp_neighbor") && p.has("clamp_neighbor")) b.desc.ic_clamp_neighbours = p.get_bool("clamp_neighbor");
        if (plugin.find("clamp_screen") && p.has("clamp_screen")) b.desc.ic_clamp_screen = p.get_bool("clamp_screen");
        // pbgi.
        const auto positive = [&](const char* name, int lo, int hi, std::optional<int>& out) {
            if (!plugin.find(name) || !p.has(name)) return;
            const int v = p.get_int(name);
            if (v < lo || v > hi) p.fail(name, fmt::format("{} must be {} to {}, got {}", name, lo, hi, v));
            out = v;
        };
        positive("surfels", 1, 10000000, b.desc.pbgi_surfels);
        positive("bounces", 1, 64, b.desc.pbgi_bounces);
        positive("buffer_resolution", 2, 256, b.desc.pbgi_resolution);
        positive("direct_samples", 1, 65536, b.desc.pbgi_direct_samples);
        positive("gather_spacing", 1, 64, b.desc.pbgi_spacing);
        positive("training_spp", 0, 1 << 20, b.desc.guiding_spp);  // ppg
        if (plugin.find("guiding_rr") && p.has("guiding_rr")) b.desc.guiding_rr = p.get_bool("guiding_rr");
        if (plugin.find("guiding_fraction") && p.has("guiding_fraction")) {
            const std::string text = p.get_string("guiding_fraction");
            if (!parse_guiding_fraction(text))
                p.fail("guiding_fraction", fmt::format("guiding_fraction must be {}, got '{}'", kGuidingFractionHelp, text));
            b.desc.guiding_fraction = text;
        }
        if (plugin.find("guiding") && p.has("guiding")) {
            const std::string text = p.get_string("guiding");
            if (!parse_guiding_model(text)) p.fail("guiding", fmt::format("guiding must be {}, got '{}'", kGuidingModelHelp, text));
            b.desc.guiding = text;
        }
        if (plugin.find("estimators") && p.has("estimators")) b.desc.estimators = p.get_string("estimators");
        if (plugin.find("photon_beams") && p.has("photon_beams")) {
            const int count = p.get_int("photon_beams");
            if (count < 0) p.fail("photon_beams", fmt::format("photon_beams must be zero (the default) or positive, got {}", count));
            b.desc.photon_beams = count;
        }
        if (plugin.find("beam_radius") && p.has("beam_radius")) {
            const float r = p.get_float("beam_radius");
            if (!(r >= 0 && std::isfinite(r))) p.fail("beam_radius", fmt::format("beam_radius must be zero (the photon radius) or positive, got {}", r));
            b.desc.beam_radius = r;
        }
        if (plugin.find("cutoff") && p.has("cutoff")) {
            const float c = p.get_float("cutoff");
            if (!(c >= 0 && c <= 4 * kPi)) p.fail("cutoff", fmt::format("cutoff must be a solid angle from 0 to 4 pi, got {}", c));
            b.desc.pbgi_cutoff = c;
        }
        p.check_all_used();
        return 0;
    });
}

// The nested integrators of a wrapper: at most one.
std::optional<pugi::xml_node> nested_integrator(XmlSource& xml, const pugi::xml_node& n, const char* type) {
    std::optional<pugi::xml_node> inner;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        if (std::string(c.name()) != "integrator") xml.fail(c, fmt::format("unsupported element <{}> in <integrator type=\"{}\">", c.name(), type));
        if (inner) xml.fail(c, fmt::format("pathlab's {} wraps one integrator, not several", type));
        inner = c;
    }
    return inner;
}

}  // namespace

std::vector<PluginInfo> integrator_wrapper_plugins() { return {moment_plugin(), aov_plugin()}; }

void read_integrator(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    if (b.have_integrator) xml.fail(n, "a scene can have only one <integrator>");
    b.have_integrator = true;
    const std::string type = xml.attr(n, "type");
    if (type == "moment") {
        Properties p = xml.properties(n, moment_plugin());
        reading([&] { return p.check_all_used(), 0; });
        const auto inner = nested_integrator(xml, n, "moment");
        if (!inner) xml.fail(n, "<integrator type=\"moment\"> wraps one nested <integrator>");
        if (std::string(inner->attribute("type").value()) == "moment") xml.fail(*inner, "a moment integrator cannot wrap another");
        b.desc.moment = true;
        b.have_integrator = false;
        read_integrator(xml, *inner, b);
        return;
    }
    if (type == "aov") {
        Properties p = xml.properties(n, aov_plugin());
        reading([&] {
            if (!p.has("aovs")) p.fail("<integrator type=\"aov\"> needs <string name=\"aovs\" value=\"name:kind, ...\"/>");
            const std::string list = p.get_string("aovs");
            for (const std::string& item : split_list(list)) {
                const size_t colon = item.find(':');
                if (colon == std::string::npos || colon == 0)
                    p.fail("aovs", fmt::format("'{}' is not name:kind (kinds: {})", item, fmt::join(kAovKinds, ", ")));
                const std::string name = item.substr(0, colon), kind = item.substr(colon + 1);
                if (std::find(std::begin(kAovKinds), std::end(kAovKinds), kind) == std::end(kAovKinds))
                    p.fail("aovs", fmt::format("unsupported aov kind '{}'; supported: {}", kind, fmt::join(kAovKinds, ", ")));
                for (const auto& [other, _] : b.desc.aovs)
                    if (other == name) p.fail("aovs", fmt::format("the aov name '{}' is given twice", name));
                b.desc.aovs.emplace_back(name, kind);
            }
            if (b.desc.aovs.empty()) p.fail("aovs", "no aov given");
            p.check_all_used();
            return 0;
        });
        if (const auto inner = nested_integrator(xml, n, "aov")) {
            if (std::string(inner->attribute("type").value()) == "aov") xml.fail(*inner, "an aov integrator cannot wrap another");
            b.have_integrator = false;
            read_integrator(xml, *inner, b);
        }
        return;
    }
    read_plain_integrator(xml, n, b);
}

}  // namespace pathlab
