// <bsdf type>: a plugin of bsdfs/registry.hpp, or a wrapper of one (twosided, normalmap,
// bumpmap). Declared at the top level with an id (referred to by <ref id>) or nested in a
// shape or a wrapper. A BSDF's parameters that may be textures (README's tables: "or texture")
// take a nested <texture name="PARAMETER"> or a <ref name="PARAMETER" id> to a top-level one.
#include <fmt/format.h>

#include "bsdfs/registry.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

// A <texture> child, or a <ref> to a declared texture.
std::shared_ptr<const Texture> texture_child(XmlSource& xml, const pugi::xml_node& c, SceneBuilder& b) {
    if (std::string(c.name()) == "texture") return read_texture(xml, c, b);
    xml.check_attributes(c, {"id", "name"});
    const std::string id = xml.attr(c, "id");
    const auto it = b.named_textures.find(id);
    if (it == b.named_textures.end()) {
        if (b.named_bsdfs.count(id)) xml.fail(c, fmt::format("'{}' is a <bsdf>, not a texture", id));
        xml.fail(c, fmt::format("no <texture> with id '{}' is declared before this reference", id));
    }
    return it->second;
}

// Whether a <ref> child names a declared BSDF (else it is taken as a texture).
bool refers_to_bsdf(XmlSource& xml, const pugi::xml_node& c, const SceneBuilder& b) {
    return std::string(c.name()) == "ref" && c.attribute("id") && b.named_bsdfs.count(xml.attr(c, "id"));
}

// The parameters of `plugin` a texture may give, for messages.
std::string texture_params(const PluginInfo& plugin) {
    std::vector<std::string> names;
    for (const ParamInfo& q : plugin.params)
        if (q.texture_slot >= 0) names.push_back(q.name);
    return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

// twosided, normalmap and bumpmap: one BSDF (nested or a <ref>), and for the last two one texture.
Material read_wrapper(XmlSource& xml, const pugi::xml_node& n, const BsdfPlugin& plugin, SceneBuilder& b) {
    const std::string type = plugin.info().type;
    std::optional<pugi::xml_node> inner, texture;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name();
        if (tag == "bsdf" || refers_to_bsdf(xml, c, b)) {
            if (inner) xml.fail(c, fmt::format("<bsdf type=\"{}\"> wraps exactly one BSDF", type));
            inner = c;
        } else if ((tag == "texture" || tag == "ref") && type != "twosided") {
            if (texture) xml.fail(c, fmt::format("<bsdf type=\"{}\"> takes exactly one texture", type));
            texture = c;
        } else if (tag == "ref" && c.attribute("id")) {
            xml.fail(c, fmt::format("no <bsdf> with id '{}' is declared before this reference", xml.attr(c, "id")));
        } else {
            xml.fail(c, fmt::format("unexpected <{}> in <bsdf type=\"{}\">; it wraps one <bsdf>{}", tag, type,
                                    type == "twosided" ? "" : " and one <texture>"));
        }
    }
    if (!inner) xml.fail(n, fmt::format("<bsdf type=\"{}\"> wraps exactly one nested <bsdf> (or a <ref> to one)", type));
    if (type != "twosided" && !texture)
        xml.fail(n, fmt::format("<bsdf type=\"{}\"> needs a texture: <texture name=\"{}\" type=\"bitmap\">...</texture> or a <ref>", type,
                                type == "normalmap" ? "normalmap" : "height"));
    if (type == "twosided" && std::string(inner->name()) == "bsdf" && std::string(inner->attribute("type").value()) == "twosided")
        xml.fail(*inner, "a twosided BSDF cannot wrap another twosided BSDF");  // (also bounds the recursion)
    if (type == "normalmap" && texture && std::string(texture->attribute("name").value()) != "normalmap")
        xml.fail(*texture, "the texture of a normalmap must be named \"normalmap\" (<texture name=\"normalmap\" ...>)");
    Properties p = xml.properties(n, plugin.info());
    const float scale = reading([&] {
        const float s = type == "bumpmap" ? p.get_float("scale") : 1.0f;
        p.check_all_used();
        return s;
    });
    const std::shared_ptr<const Texture> tex = texture ? texture_child(xml, *texture, b) : nullptr;
    Material m = std::string(inner->name()) == "bsdf" ? read_bsdf(xml, *inner, b) : b.desc.materials[b.named_bsdfs.at(xml.attr(*inner, "id"))];
    if (type == "twosided") {
        if (m.is_dielectric())
            xml.fail(*inner, fmt::format("a {} cannot be wrapped in twosided (both of its sides already matter)",
                                         std::string(inner->name()) == "bsdf" ? xml.attr(*inner, "type") : "dielectric"));
        if (m.two_sided) xml.fail(*inner, "a twosided BSDF cannot wrap another twosided BSDF");
        m.two_sided = true;
        return m;
    }
    if (m.perturbed()) xml.fail(*inner, "this BSDF already has a normal or bump map; a BSDF can have only one");
    MaterialTextures t = m.textures ? *m.textures : MaterialTextures{};
    t.perturbation = type == "normalmap" ? FramePerturbation::NormalMap : FramePerturbation::BumpMap;
    t.perturbation_texture = tex;
    t.bump_scale = scale;
    m.set_textures(std::move(t));
    return m;
}

}  // namespace

Material read_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    const BsdfPlugin* plugin = find_bsdf_plugin(type);
    if (!plugin) xml.fail(n, fmt::format("unsupported bsdf type '{}'; supported: {}", type, bsdf_type_names()));
    if (!plugin->read) return read_wrapper(xml, n, *plugin, b);

    // Textures given to parameters: each becomes a binding, and its largest value the constant
    // the plugin's reader reads (the model's lobe flags follow it; see material.hpp).
    const PluginInfo& info = plugin->info();
    std::vector<std::pair<pugi::xml_node, const ParamInfo*>> textured;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name();
        if (tag != "texture" && tag != "ref")
            xml.fail(c, fmt::format("<bsdf type=\"{}\"> has no nested <{}>; its parameters that may be textures: {}", type, tag,
                                    texture_params(info)));
        if (!c.attribute("name"))
            xml.fail(c, fmt::format("a <{}> in a <bsdf> needs the name of the parameter it gives ({})", tag, texture_params(info)));
        const std::string name = xml.attr(c, "name");
        const ParamInfo* q = info.find(name);
        if (!q || q->texture_slot < 0)
            xml.fail(c, fmt::format("parameter '{}' of <bsdf type=\"{}\"> cannot be a texture; those that can: {}", name, type,
                                    texture_params(info)));
        textured.emplace_back(c, q);
    }
    Properties p = xml.properties(n, info);
    MaterialTextures t;
    for (const auto& [c, q] : textured) {
        std::shared_ptr<const Texture> tex = texture_child(xml, c, b);
        const Rgb lo = tex->min_value(), hi = tex->max_value();
        if (min_component(lo) < 0)
            xml.fail(c, fmt::format("the texture for '{}' has negative values (down to {}); it must not be negative", q->name, min_component(lo)));
        Properties::Value v;
        v.tag = "texture";
        v.where = xml.where(c);
        v.text = q->type == ParamType::Float ? fmt::format("{:.9g}", scalar_value(hi)) : fmt::format("{:.9g}, {:.9g}, {:.9g}", hi.x, hi.y, hi.z);
        try {
            p.set(xml.attr(c, "name"), std::move(v));
        } catch (const PropertyError& e) {
            XmlSource::rethrow(e);
        }
        t.bindings.push_back({q->name, q->texture_slot, q->type == ParamType::Float, std::move(tex)});
    }
    return reading([&] {
        Material m = plugin->read(p);
        p.check_all_used();
        if (!t.bindings.empty()) m.set_textures(std::move(t));
        return m;
    });
}

void read_named_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    const auto id = xml.optional_attr(n, "id");
    if (id) b.check_new_id(xml, n, *id);
    const uint32_t index = b.add_material(read_bsdf(xml, n, b));
    if (id) b.named_bsdfs[*id] = index;
}

}  // namespace pathlab
