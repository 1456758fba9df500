// <texture type>: a plugin of textures/registry.hpp. Declared at the top level with an id
// (referred to by <ref name="PARAMETER" id>) or nested in a <bsdf> with the name of the
// parameter it gives (read_bsdf.cpp binds it).
#include <fmt/format.h>

#include "scenefile/readers.hpp"
#include "textures/registry.hpp"

namespace pathlab {

std::shared_ptr<const Texture> read_texture(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    const TexturePlugin* plugin = find_texture_plugin(type);
    if (!plugin) xml.fail(n, fmt::format("unsupported texture type '{}'; supported: {}", type, texture_type_names()));
    if (!xml.plugin_children(n).empty())
        xml.fail(xml.plugin_children(n).front(), fmt::format("<texture type=\"{}\"> has no nested plugins (its colours are constants)", type));
    Properties p = xml.properties(n, plugin->info());
    TextureContext ctx{b.shapes.base_dir, b.shapes.allow_files};
    if (ctx.allow_files) ctx.search_dirs = xml.search_dirs();
    ctx.files_read = b.shapes.files_read;
    return reading([&] {
        auto t = std::make_shared<const Texture>(plugin->read(p, ctx));
        p.check_all_used();
        return t;
    });
}

std::shared_ptr<const Texture> texture_child(XmlSource& xml, const pugi::xml_node& c, SceneBuilder& b) {
    if (std::string(c.name()) == "texture") return read_texture(xml, c, b);
    return std::any_cast<std::shared_ptr<const Texture>>(b.resolve(xml, c, "texture").value);
}

void read_named_texture(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    if (!n.attribute("id")) xml.fail(n, "a top-level <texture> needs an id (BSDFs refer to it with <ref name=\"PARAMETER\" id=\"...\"/>)");
    const std::string id = xml.attr(n, "id");
    if (n.attribute("name")) xml.fail(n, "a top-level <texture> has no name (the BSDF's <ref> names the parameter it gives)");
    if (b.named.count(id)) b.name(xml, n, id, "texture", 0);  // names the earlier declaration
    b.name(xml, n, id, "texture", read_texture(xml, n, b));
}

}  // namespace pathlab
