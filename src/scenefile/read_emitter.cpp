// <emitter type> at the top level: a plugin of lights/registry.hpp that stands on its own
// (area emitters belong inside a <shape>).
#include <fmt/format.h>

#include "scenefile/readers.hpp"

namespace pathlab {

std::shared_ptr<const SampledSpectrum> given_spectrum(Properties& p, const char* name) {
    if (!p.plugin().find(name) || !p.has(name)) return nullptr;
    const Properties::Value* v = p.given(name);
    return v ? v->spectrum : nullptr;
}

std::shared_ptr<const EmissionSpectrum> emitter_spectrum(Properties& p) {
    for (const char* name : {"radiance", "intensity", "irradiance"})
        if (const auto spectrum = given_spectrum(p, name)) {
            auto s = std::make_shared<EmissionSpectrum>();
            s->values = DenseSpectrum(*spectrum);
            s->rgb = p.get_rgb(name);  // what the emitter read
            return s;
        }
    return nullptr;
}

void read_free_emitter(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    // Mitsuba 3's spot takes a projected texture (a nested <texture name="texture"> or a <ref> to
    // one), its projector an image (<texture name="irradiance">).
    std::shared_ptr<const Texture> texture;
    const char* slot = type == "spot" ? "texture" : type == "projector" ? "irradiance" : nullptr;
    const char* what = type == "spot" ? "projected texture" : "image";
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const bool is_texture = std::string(c.name()) == "texture" || std::string(c.name()) == "ref";
        if (!slot || !is_texture)
            xml.fail(c, slot ? fmt::format("a {} emitter's only nested plugin is its <texture name=\"{}\">", type, slot)
                             : std::string("an <emitter> has no nested plugins"));
        if (std::string(c.attribute("name").value()) != slot)
            xml.fail(c, fmt::format("a {}'s {} must be named \"{}\" (<texture name=\"{}\" ...>)", type, what, slot, slot));
        if (texture) xml.fail(c, fmt::format("a {} takes one {}", type, what));
        texture = texture_child(xml, c, b);
    }
    const EmitterPlugin* plugin = find_emitter_plugin(type);
    if (plugin && !plugin->read) xml.fail(n, "an area emitter belongs inside a <shape>");
    if (!plugin)
        xml.fail(n, fmt::format("unsupported emitter type '{}'; supported: point, spot, projector, ies, constant, envmap, directional (and "
                                "area inside a shape)",
                                type));
    Properties p = xml.properties(n, plugin->info());
    EmitterContext files{b.shapes.base_dir, b.shapes.allow_files, {}, b.shapes.files_read, texture};
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
    if (auto spectrum = emitter_spectrum(p)) {
        b.desc.light_spectra.resize(b.desc.lights.size());
        b.desc.light_spectra.back() = std::move(spectrum);
    }
    if (const auto id = xml.optional_attr(n, "id")) {
        b.desc.light_ids.resize(b.desc.lights.size());
        b.desc.light_ids.back() = *id;
    }
}

}  // namespace pathlab
