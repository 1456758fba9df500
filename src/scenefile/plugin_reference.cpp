#include "scenefile/plugin_reference.hpp"

#include <fmt/format.h>

#include "bsdfs/registry.hpp"
#include "cameras/camera.hpp"
#include "geometry/shape_plugins.hpp"
#include "integrators/integrator.hpp"
#include "lights/area.hpp"
#include "lights/registry.hpp"
#include "render/film.hpp"
#include "samplers/sampler.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

// A table cell: '|' would end it.
std::string cell(const std::string& text) {
    std::string out;
    for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
}

}  // namespace

std::vector<PluginInfo> all_plugins() {
    std::vector<PluginInfo> out;
    for (const IntegratorInfo& i : integrators()) out.push_back(i.plugin());
    for (const PluginInfo& w : integrator_wrapper_plugins()) out.push_back(w);
    out.push_back(perspective_plugin());
    out.push_back(thinlens_plugin());
    out.push_back(orthographic_plugin());
    out.push_back(hdrfilm_plugin());
    for (const PluginInfo& f : rfilter_plugins()) out.push_back(f);
    out.push_back(independent_plugin());
    for (const PluginInfo& s : other_sampler_plugins()) out.push_back(s);
    for (const ShapePlugin& s : shape_plugins()) out.push_back(s.info());
    for (const PluginInfo& s : group_shape_plugins()) out.push_back(s);
    for (const BsdfPlugin& b : bsdf_plugins()) out.push_back(b.info());
    for (const EmitterPlugin& e : emitter_plugins()) out.push_back(e.info());
    return out;
}

std::string plugin_reference_markdown() {
    std::string md;
    std::string kind;
    for (const PluginInfo& p : all_plugins()) {
        if (p.kind != kind) {
            kind = p.kind;
            md += fmt::format("{}**`<{}>`**\n\n| type | parameter | value | default | meaning |\n|---|---|---|---|---|\n",
                              md.empty() ? "" : "\n", kind);
        }
        std::string type = fmt::format("`{}`", p.type);
        if (kind == "integrator")
            if (const IntegratorInfo* i = find_integrator(p.type); i && !i->aliases.empty())
                type += fmt::format(" ({})", fmt::join(i->aliases, ", "));
        md += fmt::format("| {} | | | | {} |\n", type, cell(p.summary));
        for (const ParamInfo& q : p.params) {
            const std::string name = q.old_name.empty() ? fmt::format("`{}`", q.name) : fmt::format("`{}` (`{}`)", q.name, q.old_name);
            md += fmt::format("| | {} | {} | {} | {} |\n", name, param_type_name(q.type), cell(q.default_value), cell(q.doc));
        }
    }
    return md;
}

}  // namespace pathlab
