// <shape type>: a plugin of geometry/shape_plugins.hpp, with one <bsdf> or <ref id> (default:
// one-sided diffuse 0.5) and optionally an <emitter type="area">.
#include <fmt/format.h>

#include "lights/area.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {

void read_shape(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id"});
    const std::string type = xml.attr(n, "type");
    const ShapePlugin* plugin = find_shape_plugin(type);
    if (!plugin) {
        std::vector<std::string> names;
        for (const ShapePlugin& s : shape_plugins()) names.push_back(s.info().type);
        xml.fail(n, fmt::format("unsupported shape type '{}'; supported: {}", type, fmt::join(names, ", ")));
    }

    std::optional<uint32_t> material;
    Rgb emission(0.0f);
    bool emitter = false;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name();
        if (tag == "bsdf" || tag == "ref") {
            if (material) xml.fail(c, "a shape can have only one BSDF");
            if (tag == "bsdf") {
                if (c.attribute("id")) xml.fail(c, "a nested <bsdf> cannot have an id; declare it at the top level and use <ref>");
                material = b.add_material(read_bsdf(xml, c, b));
            } else {
                xml.check_attributes(c, {"id", "name"});
                const std::string id = xml.attr(c, "id");
                const auto it = b.named_bsdfs.find(id);
                if (b.named_textures.count(id)) xml.fail(c, fmt::format("'{}' is a texture, not a <bsdf>; textures are given to a BSDF's parameters", id));
                if (it == b.named_bsdfs.end()) xml.fail(c, fmt::format("no <bsdf> with id '{}' is declared before this reference", id));
                material = it->second;
            }
        } else if (tag == "emitter") {
            xml.check_attributes(c, {"type", "id", "name"});
            const std::string etype = xml.attr(c, "type");
            if (etype != area_plugin().type) xml.fail(c, fmt::format("a shape's emitter must be of type 'area', not '{}'", etype));
            if (emitter) xml.fail(c, "a shape can have only one emitter");
            if (!xml.plugin_children(c).empty()) xml.fail(xml.plugin_children(c).front(), "an <emitter> has no nested plugins");
            Properties ep = xml.properties(c, area_plugin());
            emission = reading([&] {
                const Rgb L = read_area_radiance(ep);
                ep.check_all_used();
                return L;
            });
            emitter = true;
        } else {
            xml.fail(c, fmt::format("unsupported element <{}> in <shape>; supported: <bsdf>, <ref>, <emitter>", tag));
        }
    }
    if (!material) {
        if (!b.default_material) {
            Material m = make_phong(Rgb(0.5f));
            m.two_sided = false;
            b.default_material = b.add_material(m);
        }
        material = *b.default_material;
    }

    Properties p = xml.properties(n, plugin->info());
    ShapeDesc shape = reading([&] {
        ShapeDesc s = plugin->read(p, b.shapes);
        p.check_all_used();
        return s;
    });
    if (auto* sphere = std::get_if<SphereDesc>(&shape)) {
        sphere->material = *material;
        sphere->emission = emission;
        b.desc.spheres.push_back(*sphere);
        return;
    }
    MeshDesc& m = std::get<MeshDesc>(shape);
    if (m.name.empty()) m.name = type;
    if (const auto id = xml.optional_attr(n, "id")) m.name = *id;
    m.material = *material;
    m.emission = emission;
    b.desc.meshes.push_back(std::move(m));
}

}  // namespace pathlab
