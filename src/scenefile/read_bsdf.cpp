// <bsdf type>: a plugin of bsdfs/registry.hpp, or a wrapper of nested BSDFs (twosided with one
// or two, blendbsdf with two, mask, normalmap and bumpmap with one), each nested one a <bsdf>
// or a <ref id>. Declared at the top level with an id (referred to by <ref id>) or nested in a
// shape or a wrapper. A BSDF's parameters that may be textures (docs/scene-files.md's tables: "or texture",
// also blendbsdf's weight and mask's opacity) take a nested <texture name="PARAMETER"> or a
// <ref name="PARAMETER" id> to a top-level one.
#include <fmt/format.h>

#include "bsdfs/registry.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

constexpr int kMaxNesting = 16;  // wrappers of wrappers (also bounds the recursion on hostile files)

Material read_bsdf_at(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b, int depth);

// The kind of object a <ref> child names ("" when its id is not declared).
std::string ref_kind(XmlSource& xml, const pugi::xml_node& c, const SceneBuilder& b) {
    if (std::string(c.name()) != "ref" || !c.attribute("id")) return "";
    const auto it = b.named.find(xml.attr(c, "id"));
    return it == b.named.end() ? "" : it->second.kind;
}

// The parameters of `plugin` a texture may give, for messages.
std::string texture_params(const PluginInfo& plugin) {
    std::vector<std::string> names;
    for (const ParamInfo& q : plugin.params)
        if (q.texture_slot >= 0) names.push_back(q.name);
    return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

// A texture given to parameter q: checked (not negative), its largest value set in p as the
// constant the reader reads (the model's lobe flags follow it; see material.hpp), and its binding.
TextureBinding bind_texture(XmlSource& xml, const pugi::xml_node& c, const ParamInfo& q, Properties& p, SceneBuilder& b) {
    std::shared_ptr<const Texture> tex = texture_child(xml, c, b);
    const Rgb lo = tex->min_value(), hi = tex->max_value();
    if (min_component(lo) < 0)
        xml.fail(c, fmt::format("the texture for '{}' has negative values (down to {}); it must not be negative", q.name, min_component(lo)));
    Properties::Value v;
    v.tag = "texture";
    v.where = xml.where(c);
    v.text = q.type == ParamType::Float ? fmt::format("{:.9g}", scalar_value(hi)) : fmt::format("{:.9g}, {:.9g}, {:.9g}", hi.x, hi.y, hi.z);
    try {
        p.set(q.name, std::move(v));
    } catch (const PropertyError& e) {
        XmlSource::rethrow(e);
    }
    return {q.name, q.texture_slot, q.type == ParamType::Float, std::move(tex)};
}

// A float parameter of a wrapper in [0, 1] (weight, opacity; of a texture: its largest value).
float unit_parameter(Properties& p, const std::string& name) {
    const float v = p.get_float(name);
    if (!(v >= 0 && v <= 1)) p.fail(name, fmt::format("{} must be between 0 and 1, got {}", name, v));
    return v;
}

// twosided, blendbsdf, mask, normalmap and bumpmap.
Material read_wrapper(XmlSource& xml, const pugi::xml_node& n, const BsdfPlugin& plugin, SceneBuilder& b, int depth) {
    const std::string type = plugin.info().type;
    // The name a texture child must have ("": any; bumpmap's height texture may be named anything).
    const std::string texture_name = type == "blendbsdf" ? "weight" : type == "mask" ? "opacity" : type == "normalmap" ? "normalmap" : "";
    const bool takes_texture = type != "twosided";
    std::vector<pugi::xml_node> nested;
    std::optional<pugi::xml_node> texture;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        const std::string tag = c.name(), kind = ref_kind(xml, c, b);
        const std::string name = c.attribute("name").value();
        bool is_texture = tag == "texture" || kind == "texture";
        if (tag == "ref" && kind.empty() && takes_texture && c.attribute("name") && (texture_name.empty() || name == texture_name))
            is_texture = true;  // an undeclared texture: texture_child names it
        if (tag == "bsdf" || (tag == "ref" && !is_texture)) {
            nested.push_back(c);
        } else if (is_texture && takes_texture) {
            if (texture) xml.fail(c, fmt::format("<bsdf type=\"{}\"> takes exactly one texture", type));
            if (!texture_name.empty() && name != texture_name)
                xml.fail(c, fmt::format("the texture of a {} must be named \"{}\" (<texture name=\"{}\" ...>)", type, texture_name, texture_name));
            texture = c;
        } else {
            xml.fail(c, fmt::format("unsupported element <{}> in <bsdf type=\"{}\">; supported: <bsdf>, <ref>{}", tag, type,
                                    takes_texture ? ", <texture>" : ""));
        }
    }
    if (type == "normalmap" || type == "bumpmap") {
        if (nested.size() != 1) xml.fail(n, fmt::format("<bsdf type=\"{}\"> wraps exactly one nested <bsdf> (or a <ref> to one)", type));
        if (!texture)
            xml.fail(n, fmt::format("<bsdf type=\"{}\"> needs a texture: <texture name=\"{}\" type=\"bitmap\">...</texture> or a <ref>", type,
                                    type == "normalmap" ? "normalmap" : "height"));
    }
    Properties p = xml.properties(n, plugin.info());
    std::optional<TextureBinding> binding;
    if (texture && (type == "blendbsdf" || type == "mask")) binding = bind_texture(xml, *texture, *plugin.info().find(texture_name), p, b);
    std::vector<Material> inner;
    for (const pugi::xml_node& c : nested) inner.push_back(read_bsdf_at(xml, c, b, depth + 1));
    const auto what = [&](size_t i) { return std::string(nested[i].name()) == "bsdf" ? xml.attr(nested[i], "type") : "dielectric"; };
    const auto no_transmission = [&](const Material& m, size_t i) {
        if (m.is_dielectric()) xml.fail(nested[i], fmt::format("a {} cannot be wrapped in {} (both of its sides already matter)", what(i), type));
    };
    const auto no_perturbation = [&](const Material& m, size_t i) {
        if (m.perturbed())
            xml.fail(nested[i], fmt::format("a normal or bump map inside {} is not supported (the {} has one shading frame): wrap the {} "
                                            "in the normalmap or bumpmap instead", type, type, type));
    };
    if (type == "twosided") {
        if (inner.size() != 1 && inner.size() != 2)
            xml.fail(n, "<bsdf type=\"twosided\"> wraps one nested BSDF (both sides) or two (front, back)");
        reading([&] { return p.check_all_used(), 0; });
        for (size_t i = 0; i < inner.size(); ++i) {
            no_transmission(inner[i], i);
            if (inner[i].two_sided && std::string(nested[i].attribute("type").value()) == "twosided")
                xml.fail(nested[i], "a twosided BSDF cannot wrap another twosided BSDF");
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
    if (type == "blendbsdf" || type == "mask") {
        const bool blend = type == "blendbsdf";
        if (inner.size() != (blend ? 2u : 1u))
            xml.fail(n, blend ? "<bsdf type=\"blendbsdf\"> wraps exactly two nested BSDFs" : "<bsdf type=\"mask\"> wraps exactly one nested BSDF");
        const float w = reading([&] {
            const float v = unit_parameter(p, blend ? "weight" : "opacity");
            p.check_all_used();
            return v;
        });
        for (size_t i = 0; i < inner.size(); ++i) no_transmission(inner[i], i), no_perturbation(inner[i], i);
        Material m;
        if (blend) {
            if (inner[0].two_sided != inner[1].two_sided)
                xml.fail(n, "blendbsdf of a one-sided and a two-sided BSDF: wrap the blend in twosided instead");
            if (inner[0].back >= 0 || inner[1].back >= 0) xml.fail(n, "blendbsdf of a twosided BSDF with two sides is not supported");
            m = Material{BlendMaterial{std::make_shared<const Material>(inner[0]), std::make_shared<const Material>(inner[1]), w}, inner[0].two_sided};
        } else {
            if (inner[0].back >= 0) xml.fail(n, "a mask over a twosided BSDF with two sides is not supported");
            m = Material{MaskMaterial{std::make_shared<const Material>(inner[0]), w}, inner[0].two_sided};
        }
        if (binding) {
            MaterialTextures t;
            t.bindings.push_back(std::move(*binding));
            m.set_textures(std::move(t));
        } else {
            m.prepare();  // (its nested materials may vary)
        }
        return m;
    }
    // normalmap, bumpmap
    bool flip = true, shadowing = true;
    const float scale = reading([&] {
        const float s = type == "bumpmap" ? p.get_float("scale") : 1.0f;
        if (p.has("flip_invalid_normals")) flip = p.get_bool("flip_invalid_normals");
        if (p.has("use_shadowing_function")) shadowing = p.get_bool("use_shadowing_function");
        p.check_all_used();
        return s;
    });
    const std::shared_ptr<const Texture> tex = texture_child(xml, *texture, b);
    Material m = inner[0];
    if (m.perturbed()) xml.fail(nested[0], "this BSDF already has a normal or bump map; a BSDF can have only one");
    if (m.back >= 0)
        xml.fail(nested[0], fmt::format("a {} over a twosided BSDF with two sides is not supported: put a {} inside each side", type, type));
    MaterialTextures t = m.textures ? *m.textures : MaterialTextures{};
    t.perturbation = type == "normalmap" ? FramePerturbation::NormalMap : FramePerturbation::BumpMap;
    t.perturbation_texture = tex;
    t.bump_scale = scale;
    t.flip_invalid_normals = flip;
    t.shadowing_function = shadowing;
    m.set_textures(std::move(t));
    return m;
}

// The model's reflectances that the file gave as spectra (MaterialSpectra), or null.
std::shared_ptr<const MaterialSpectra> reflectance_spectra(Properties& p, const MaterialModel& model) {
    const auto given = [&](std::initializer_list<const char*> names) -> std::shared_ptr<const DenseSpectrum> {
        for (const char* name : names)
            if (const auto spectrum = given_spectrum(p, name)) return std::make_shared<const DenseSpectrum>(*spectrum);
        return nullptr;
    };
    MaterialSpectra s;
    if (std::holds_alternative<PhongMaterial>(model) || std::holds_alternative<PlasticMaterial>(model) ||
        std::holds_alternative<RoughPlasticMaterial>(model))
        s.diffuse = given({"reflectance", "diffuse_reflectance"});
    if (!std::holds_alternative<DielectricMaterial>(model) && !std::holds_alternative<RoughDielectricMaterial>(model) &&
        !std::holds_alternative<ThinDielectricMaterial>(model))
        s.specular = given({"specular_reflectance"});
    if (!s.diffuse && !s.specular) return nullptr;
    return std::make_shared<const MaterialSpectra>(std::move(s));
}

Material read_bsdf_at(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b, int depth) {
    if (depth > kMaxNesting) xml.fail(n, fmt::format("BSDFs nested more than {} deep", kMaxNesting));
    if (std::string(n.name()) == "ref") {
        const NamedObject& o = b.resolve(xml, n, "bsdf");
        if (o.value.type() == typeid(NullBsdf))
            xml.fail(n, "a null BSDF is a shape's own BSDF (nested in it, or declared with an id); nothing wraps it");
        return b.desc.materials[std::any_cast<uint32_t>(o.value)];
    }
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    const BsdfPlugin* plugin = find_bsdf_plugin(type);
    if (type == null_bsdf_plugin().type) xml.fail(n, "a null BSDF is a shape's own BSDF (nested in it, or declared with an id); nothing wraps it");
    if (!plugin) xml.fail(n, fmt::format("unsupported bsdf type '{}'; supported: {}", type, bsdf_type_names()));
    if (!plugin->read) return read_wrapper(xml, n, *plugin, b, depth);

    // Textures given to parameters: each becomes a binding.
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
    for (const auto& [c, q] : textured) t.bindings.push_back(bind_texture(xml, c, *q, p, b));
    return reading([&] {
        Material m = plugin->read(p);
        m.spectra = reflectance_spectra(p, m.model);
        p.check_all_used();
        if (!t.bindings.empty()) m.set_textures(std::move(t));
        return m;
    });
}

}  // namespace

Material read_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) { return read_bsdf_at(xml, n, b, 0); }

void read_named_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    const auto id = xml.optional_attr(n, "id");
    if (xml.optional_attr(n, "type") == null_bsdf_plugin().type) {  // no material: a medium boundary
        xml.check_attributes(n, {"type", "id"});
        if (!xml.plugin_children(n).empty()) xml.fail(xml.plugin_children(n).front(), "a null BSDF has no nested plugins");
        Properties p = xml.properties(n, null_bsdf_plugin());
        reading([&] { return p.check_all_used(), 0; });
        if (id) b.name(xml, n, *id, "bsdf", NullBsdf{});
        return;
    }
    if (id && b.named.count(*id)) b.name(xml, n, *id, "bsdf", uint32_t(0));  // names the earlier declaration
    const uint32_t index = b.add_material(read_bsdf(xml, n, b));
    if (id) {
        b.name(xml, n, *id, "bsdf", index);
        b.name_material(index, *id);
    }
}

}  // namespace pathlab
