// <emitter type> at the top level: a plugin of lights/registry.hpp that stands on its own
// (area emitters belong inside a <shape>).
#include <fmt/format.h>

#include "scenefile/readers.hpp"

namespace pathlab {

void read_free_emitter(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        // Mitsuba 3's spot takes a projected texture: a nested <texture name="texture">.
        if (type == "spot" && (std::string(c.name()) == "texture" || std::string(c.attribute("name").value()) == "texture"))
            xml.fail(c, "a spot's projected texture is not supported yet (pathlab's spot has a uniform beam)");
        xml.fail(c, "an <emitter> has no nested plugins");
    }
    const EmitterPlugin* plugin = find_emitter_plugin(type);
    if (plugin && !plugin->read) xml.fail(n, "an area emitter belongs inside a <shape>");
    if (!plugin)
        xml.fail(n, fmt::format("unsupported emitter type '{}'; supported: point, spot, ies, constant, envmap, directional (and "
                                "area inside a shape)",
                                type));
    Properties p = xml.properties(n, plugin->info());
    EmitterContext files{b.shapes.base_dir, b.shapes.allow_files};
    if (files.allow_files) files.search_dirs = xml.search_dirs();
    const FreeLight light = reading([&] {
        FreeLight l = plugin->read(p, files);
        p.check_all_used();
        return l;
    });
    const auto environment = [](const FreeLight& l) {
        return std::holds_alternative<EnvironmentLight>(l) || std::holds_alternative<EnvMapLight>(l);
    };
    if (environment(light))
        for (const FreeLight& l : b.desc.lights)
            if (environment(l)) xml.fail(n, "a scene can have only one environment emitter (constant or envmap)");
    b.desc.lights.push_back(light);
}

}  // namespace pathlab
