// <bsdf type>: a plugin of bsdfs/registry.hpp, or a wrapper of nested BSDFs (twosided with one
// or two, blendbsdf with two, mask with one), each nested one a <bsdf> or a <ref id>. Declared
// at the top level with an id (referred to by <ref id>) or nested in a shape.
#include <fmt/format.h>

#include "bsdfs/registry.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

constexpr int kMaxNesting = 16;  // wrappers of wrappers (also bounds the recursion on hostile files)

Material read_bsdf_at(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b, int depth);

// The nested BSDFs of a wrapper (<bsdf> or <ref>; a <texture> or <spectrum> parameter is named).
std::vector<Material> nested_bsdfs(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b, int depth, const std::string& type) {
    std::vector<Material> out;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name();
        if (tag == "texture") xml.fail(c, fmt::format("a <texture> in <bsdf type=\"{}\"> needs textures, which pathlab does not have yet; give a constant <float>", type));
        if (tag != "bsdf" && tag != "ref") xml.fail(c, fmt::format("unsupported element <{}> in <bsdf type=\"{}\">; supported: <bsdf>, <ref>", tag, type));
        out.push_back(read_bsdf_at(xml, c, b, depth + 1));
    }
    return out;
}

// A float parameter of a wrapper in [0, 1] (weight, opacity); a texture reference is refused.
float unit_parameter(Properties& p, const std::string& name) {
    const float v = p.get_float(name);
    if (!(v >= 0 && v <= 1)) p.fail(name, fmt::format("{} must be between 0 and 1, got {}", name, v));
    return v;
}

Material read_bsdf_at(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b, int depth) {
    if (depth > kMaxNesting) xml.fail(n, fmt::format("BSDFs nested more than {} deep", kMaxNesting));
    if (std::string(n.name()) == "ref") {
        const NamedObject& o = b.resolve(xml, n, "bsdf");
        return b.desc.materials[std::any_cast<uint32_t>(o.value)];
    }
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    if (type == "principled" || type == "principledthin")
        xml.fail(n, fmt::format("unsupported bsdf type '{}': pathlab has no principled (Disney) model, so base_color, metallic, "
                                "specular, roughness, spec_tint, anisotropic, sheen, clearcoat and spec_trans cannot be honoured; "
                                "use roughplastic (a dielectric coat over a base colour) or roughconductor (metallic = 1)", type));
    if (type == "null") xml.fail(n, "unsupported bsdf type 'null': it marks a medium's boundary, and pathlab has no participating media yet");
    const BsdfPlugin* plugin = find_bsdf_plugin(type);
    if (!plugin) xml.fail(n, fmt::format("unsupported bsdf type '{}'; supported: {}", type, bsdf_type_names()));
    if (!plugin->read) {  // a wrapper
        for (const pugi::xml_node& c : n.children())
            if (std::string(c.name()) == "texture" || (std::string(c.name()) == "ref" && c.attribute("name") &&
                                                         (std::string(c.attribute("name").value()) == "weight" ||
                                                          std::string(c.attribute("name").value()) == "opacity")))
                xml.fail(c, fmt::format("a texture for <bsdf type=\"{}\"> needs textures, which pathlab does not have yet; give a constant <float>", type));
        std::vector<Material> inner = nested_bsdfs(xml, n, b, depth, type);
        Properties p = xml.properties(n, plugin->info());
        const auto no_transmission = [&](const Material& m, size_t i) {
            const pugi::xml_node c = xml.plugin_children(n)[i];
            const std::string what = std::string(c.name()) == "bsdf" ? xml.attr(c, "type") : "dielectric";
            if (m.is_dielectric())
                xml.fail(c, fmt::format("a {} cannot be wrapped in {} (both of its sides already matter)", what, type));
        };
        if (type == "twosided") {
            if (inner.size() != 1 && inner.size() != 2)
                xml.fail(n, "<bsdf type=\"twosided\"> wraps one nested BSDF (both sides) or two (front, back)");
            reading([&] { return p.check_all_used(), 0; });
            for (size_t i = 0; i < inner.size(); ++i) {
                no_transmission(inner[i], i);
                if (inner[i].two_sided && std::string(xml.plugin_children(n)[i].attribute("type").value()) == "twosided")
                    xml.fail(xml.plugin_children(n)[i], "a twosided BSDF cannot wrap another twosided BSDF");
            }
            Material m = inner[0];
            m.two_sided = true;
            if (inner.size() == 2) {
                Material back = inner[1];
                back.two_sided = true;
                back.back = -1;
                m.back = int32_t(b.add_material(back));
            }
            return m;
        }
        if (type == "blendbsdf") {
            if (inner.size() != 2) xml.fail(n, "<bsdf type=\"blendbsdf\"> wraps exactly two nested BSDFs");
            const float w = reading([&] {
                const float v = unit_parameter(p, "weight");
                p.check_all_used();
                return v;
            });
            for (size_t i = 0; i < 2; ++i) no_transmission(inner[i], i);
            if (inner[0].two_sided != inner[1].two_sided)
                xml.fail(n, "blendbsdf of a one-sided and a two-sided BSDF: wrap the blend in twosided instead");
            if (inner[0].back >= 0 || inner[1].back >= 0) xml.fail(n, "blendbsdf of a twosided BSDF with two sides is not supported");
            const bool two_sided = inner[0].two_sided;
            return Material{BlendMaterial{std::make_shared<const Material>(inner[0]), std::make_shared<const Material>(inner[1]), w}, two_sided};
        }
        // mask
        if (inner.size() != 1) xml.fail(n, "<bsdf type=\"mask\"> wraps exactly one nested BSDF");
        const float opacity = reading([&] {
            const float v = unit_parameter(p, "opacity");
            p.check_all_used();
            return v;
        });
        no_transmission(inner[0], 0);
        if (inner[0].back >= 0) xml.fail(n, "a mask over a twosided BSDF with two sides is not supported");
        return Material{MaskMaterial{std::make_shared<const Material>(inner[0]), opacity}, inner[0].two_sided};
    }
    if (!xml.plugin_children(n).empty()) {
        const pugi::xml_node c = xml.plugin_children(n).front();
        if (std::string(c.name()) == "texture")
            xml.fail(c, fmt::format("a <texture> in <bsdf type=\"{}\"> needs textures, which pathlab does not have yet; give a constant value", type));
        xml.fail(c, fmt::format("<bsdf type=\"{}\"> has no nested plugins", type));
    }
    Properties p = xml.properties(n, plugin->info());
    return reading([&] {
        Material m = plugin->read(p);
        p.check_all_used();
        return m;
    });
}

}  // namespace

Material read_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) { return read_bsdf_at(xml, n, b, 0); }

void read_named_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    const auto id = xml.optional_attr(n, "id");
    if (id && b.named.count(*id)) b.name(xml, n, *id, "bsdf", uint32_t(0));  // names the earlier declaration
    const uint32_t index = b.add_material(read_bsdf(xml, n, b));
    if (id) b.name(xml, n, *id, "bsdf", index);
}

}  // namespace pathlab
