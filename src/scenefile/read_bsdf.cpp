// <bsdf type>: a plugin of bsdfs/registry.hpp, or twosided wrapping one of them. Declared at
// the top level with an id (referred to by <ref id>) or nested in a shape.
#include <fmt/format.h>

#include "bsdfs/registry.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {

Material read_bsdf(XmlSource& xml, const pugi::xml_node& n) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    const BsdfPlugin* plugin = find_bsdf_plugin(type);
    if (type == null_bsdf_plugin().type) xml.fail(n, "a null BSDF is a shape's own BSDF (nested in it, or declared with an id); nothing wraps it");
    if (!plugin) xml.fail(n, fmt::format("unsupported bsdf type '{}'; supported: {}", type, bsdf_type_names()));
    if (!plugin->read) {  // twosided
        std::vector<pugi::xml_node> inner = xml.plugin_children(n);
        if (inner.size() != 1 || std::string(inner[0].name()) != "bsdf") xml.fail(n, "<bsdf type=\"twosided\"> wraps exactly one nested <bsdf>");
        if (std::string(inner[0].attribute("type").value()) == "twosided")  // also bounds the recursion
            xml.fail(inner[0], "a twosided BSDF cannot wrap another twosided BSDF");
        Properties p = xml.properties(n, plugin->info());
        reading([&] { return p.check_all_used(), 0; });
        Material m = read_bsdf(xml, inner[0]);
        if (m.is_dielectric())
            xml.fail(inner[0], fmt::format("a {} cannot be wrapped in twosided (both of its sides already matter)", xml.attr(inner[0], "type")));
        m.two_sided = true;
        return m;
    }
    if (!xml.plugin_children(n).empty())
        xml.fail(xml.plugin_children(n).front(), fmt::format("<bsdf type=\"{}\"> has no nested plugins", type));
    Properties p = xml.properties(n, plugin->info());
    return reading([&] {
        Material m = plugin->read(p);
        p.check_all_used();
        return m;
    });
}

void read_named_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    const auto id = xml.optional_attr(n, "id");
    if (xml.optional_attr(n, "type") == null_bsdf_plugin().type) {  // no material: a medium boundary
        xml.check_attributes(n, {"type", "id"});
        if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "a null BSDF has no nested plugins");
        Properties p = xml.properties(n, null_bsdf_plugin());
        reading([&] { return p.check_all_used(), 0; });
        if (id && (b.named_bsdfs.count(*id) || b.null_bsdfs.count(*id))) xml.fail(n, fmt::format("the id '{}' is already used", *id));
        if (id) b.null_bsdfs.insert(*id);
        return;
    }
    const uint32_t index = b.add_material(read_bsdf(xml, n));
    if (id) {
        if (b.named_bsdfs.count(*id) || b.null_bsdfs.count(*id)) xml.fail(n, fmt::format("the id '{}' is already used", *id));
        b.named_bsdfs[*id] = index;
    }
}

}  // namespace pathlab
