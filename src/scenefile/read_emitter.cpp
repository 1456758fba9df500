// <emitter type> at the top level: a plugin of lights/registry.hpp that stands on its own
// (area emitters belong inside a <shape>).
#include <fmt/format.h>

#include "scenefile/readers.hpp"

namespace pathlab {

void read_free_emitter(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "an <emitter> has no nested plugins");
    const EmitterPlugin* plugin = find_emitter_plugin(type);
    if (plugin && !plugin->read) xml.fail(n, "an area emitter belongs inside a <shape>");
    if (!plugin)
        xml.fail(n, fmt::format("unsupported emitter type '{}'; supported: point, constant, directional (and area inside a "
                                "shape){}", type, type == "envmap" || type == "spot" ? " (envmap and spot are being added)" : ""));
    Properties p = xml.properties(n, plugin->info());
    const FreeLight light = reading([&] {
        FreeLight l = plugin->read(p);
        p.check_all_used();
        return l;
    });
    if (std::holds_alternative<EnvironmentLight>(light))
        for (const FreeLight& l : b.desc.lights)
            if (std::holds_alternative<EnvironmentLight>(l)) xml.fail(n, "a scene can have only one constant emitter");
    b.desc.lights.push_back(light);
}

}  // namespace pathlab
