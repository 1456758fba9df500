// <shape type>: a plugin of geometry/shape_plugins.hpp, with one <bsdf> or <ref id> (default:
// one-sided diffuse 0.5), optionally an <emitter type="area">, and the media on its two sides
// (<medium name="interior|exterior"> or <ref name="interior|exterior" id>). A null BSDF, or
// media without any BSDF (as Mitsuba 0.6 read it; Mitsuba 3 would give such a shape its default
// diffuse BSDF), makes the shape an index-matched boundary between its media.
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
    bool null_bsdf = false;
    MediumInterface media;
    Rgb emission(0.0f);
    bool emitter = false;
    // A medium on one side: name="interior" or "exterior".
    const auto medium_side = [&](const pugi::xml_node& c) -> int32_t& {
        const std::string side = xml.attr(c, "name");
        if (side != "interior" && side != "exterior")
            xml.fail(c, fmt::format("a shape's medium is named interior or exterior, not '{}'", side));
        int32_t& slot = side == "interior" ? media.interior : media.exterior;
        if (slot >= 0) xml.fail(c, fmt::format("the shape already has an {} medium", side));
        return slot;
    };
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name();
        if (tag == "medium") {
            int32_t& slot = medium_side(c);
            slot = read_medium(xml, c, b);
        } else if (tag == "ref" && (std::string(c.attribute("name").value()) == "interior" ||
                                    std::string(c.attribute("name").value()) == "exterior")) {
            xml.check_attributes(c, {"id", "name"});
            int32_t& slot = medium_side(c);
            slot = medium_reference(xml, c, b);
        } else if (tag == "bsdf" || tag == "ref") {
            if (material || null_bsdf) xml.fail(c, "a shape can have only one BSDF");
            if (tag == "bsdf" && xml.optional_attr(c, "type") == null_bsdf_plugin().type) {
                xml.check_attributes(c, {"type", "name"});
                if (!xml.plugin_children(c).empty()) xml.fail(xml.plugin_children(c).front(), "a null BSDF has no nested plugins");
                Properties np = xml.properties(c, null_bsdf_plugin());
                reading([&] { return np.check_all_used(), 0; });
                null_bsdf = true;
            } else if (tag == "bsdf") {
                if (c.attribute("id")) xml.fail(c, "a nested <bsdf> cannot have an id; declare it at the top level and use <ref>");
                material = b.add_material(read_bsdf(xml, c));
            } else {
                xml.check_attributes(c, {"id", "name"});
                const std::string id = xml.attr(c, "id");
                const auto it = b.named_bsdfs.find(id);
                if (b.null_bsdfs.count(id)) {
                    null_bsdf = true;
                } else if (it == b.named_bsdfs.end()) {
                    xml.fail(c, b.named_media.count(id)
                                    ? fmt::format("'{}' is a medium: refer to it with name=\"interior\" or name=\"exterior\"", id)
                                    : fmt::format("no <bsdf> with id '{}' is declared before this reference", id));
                } else {
                    material = it->second;
                }
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
            xml.fail(c, fmt::format("unsupported element <{}> in <shape>; supported: <bsdf>, <ref>, <emitter>, <medium>", tag));
        }
    }
    media.index_matched = null_bsdf || (!material && !emitter && media.changes_medium());
    if (media.index_matched && emitter) xml.fail(n, "a shape with a null BSDF cannot emit light in pathlab (give it a BSDF)");
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
        sphere->media = media;
        b.desc.spheres.push_back(*sphere);
        return;
    }
    MeshDesc& m = std::get<MeshDesc>(shape);
    if (m.name.empty()) m.name = type;
    if (const auto id = xml.optional_attr(n, "id")) m.name = *id;
    m.material = *material;
    m.emission = emission;
    m.media = media;
    b.desc.meshes.push_back(std::move(m));
}

}  // namespace pathlab
