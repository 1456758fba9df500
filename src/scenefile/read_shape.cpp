// <shape type>: a plugin of geometry/shape_plugins.hpp, with one <bsdf> or <ref id> (default:
// one-sided diffuse 0.5), optionally an <emitter type="area">, and the media on its two sides
// (<medium name="interior|exterior"> or <ref name="interior|exterior" id>); or a shapegroup
// (meshes placed by instances, through Embree instancing) and its instances. A null BSDF, or
// media without any BSDF (as Mitsuba 0.6 read it; Mitsuba 3 would give such a shape its default
// diffuse BSDF), makes the shape an index-matched boundary between its media.
#include <fmt/format.h>

#include "lights/area.hpp"
#include "scenefile/readers.hpp"

namespace pathlab {
namespace {

const PluginInfo& shapegroup_plugin() {
    static const PluginInfo info{"shape", "shapegroup",
                                 "meshes and spheres (nested <shape>s, not emitters) placed by instances (meshes stored once; spheres copied, "
                                 "their instances rotated, scaled uniformly, moved); needs an id", {}};
    return info;
}
const PluginInfo& instance_plugin() {
    static const PluginInfo info{"shape", "instance", "a shapegroup (<ref id>) placed by to_world (Embree instancing)",
                                 {{"to_world", ParamType::Transform, "", "placement of the group", "toWorld"}}};
    return info;
}

// `group`: the shape belongs to a shapegroup (its mesh goes there; a sphere to `group_spheres`).
void read_shape_into(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b, std::vector<MeshDesc>* group,
                     std::vector<SphereDesc>* group_spheres = nullptr);

// A material whose textures read the mesh's own attributes (mesh_attribute) needs a mesh that
// has each of them (one channel where a float parameter reads it), with values in [0, 1] (the
// range its texture declared when it was read, before any mesh was known).
void check_mesh_attributes(XmlSource& xml, const pugi::xml_node& n, const SceneBuilder& b, uint32_t material, const ShapeDesc& shape,
                           bool in_group) {
    const Material& m = b.desc.materials[material];
    std::vector<Material::AttributeUse> uses = m.mesh_attributes_read();
    if (m.back >= 0)
        for (Material::AttributeUse& u : b.desc.materials[size_t(m.back)].mesh_attributes_read()) uses.push_back(std::move(u));
    if (uses.empty()) return;
    const MeshDesc* mesh = std::get_if<MeshDesc>(&shape);
    if (!mesh) xml.fail(n, fmt::format("its BSDF reads the mesh attribute '{}' (mesh_attribute), and a sphere has none", uses[0].name));
    if (in_group)
        xml.fail(n, fmt::format("its BSDF reads the mesh attribute '{}' (mesh_attribute), which an instance's mesh does not keep: place the shape "
                                "on its own",
                                uses[0].name));
    for (const Material::AttributeUse& u : uses) {
        const MeshAttribute* a = find_attribute(mesh->attributes, u.name);
        if (!a) {
            std::vector<std::string> names;
            for (const MeshAttribute& x : mesh->attributes) names.push_back(x.name);
            xml.fail(n, fmt::format("its BSDF reads the mesh attribute '{}' (mesh_attribute), which mesh '{}' does not have; it has: {}", u.name,
                                    mesh->name, names.empty() ? std::string("none (only PLY files give attributes)") : fmt::format("{}", fmt::join(names, ", "))));
        }
        if (u.scalar && a->channels != 1)
            xml.fail(n, fmt::format("the mesh attribute '{}' has {} channels, and the parameter reading it takes one value", u.name, a->channels));
        if (a->min_value() < 0 || a->max_value() > 1)
            xml.fail(n, fmt::format("the mesh attribute '{}' of mesh '{}' has values from {} to {}; a mesh_attribute texture takes values in [0, 1] "
                                    "(its scale multiplies them)",
                                    u.name, mesh->name, a->min_value(), a->max_value()));
    }
}

void read_shapegroup(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    const auto id = xml.optional_attr(n, "id");
    if (!id) xml.fail(n, "a shapegroup needs an id (instances refer to it)");
    Properties p = xml.properties(n, shapegroup_plugin());
    reading([&] { return p.check_all_used(), 0; });
    ShapeGroupDesc g;
    g.name = *id;
    std::vector<SphereDesc> spheres;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        if (std::string(c.name()) != "shape") xml.fail(c, fmt::format("unsupported element <{}> in a shapegroup; supported: <shape>", c.name()));
        const std::string type = c.attribute("type").value();
        if (type == "shapegroup" || type == "instance") xml.fail(c, "shapegroups and instances cannot be nested in a shapegroup");
        read_shape_into(xml, c, b, &g.meshes, &spheres);
    }
    if (g.meshes.empty() && spheres.empty()) xml.fail(n, "an empty shapegroup");
    b.desc.groups.push_back(std::move(g));
    b.group_spheres.resize(b.desc.groups.size());
    b.group_spheres.back() = std::move(spheres);
    b.name(xml, n, *id, "shapegroup", uint32_t(b.desc.groups.size() - 1));
}

void read_instance(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) {
    std::optional<uint32_t> group;
    for (const pugi::xml_node& c : xml.plugin_children(n)) {
        if (std::string(c.name()) != "ref" || group)
            xml.fail(c, "an instance has exactly one <ref id> to a shapegroup (and its to_world)");
        group = std::any_cast<uint32_t>(b.resolve(xml, c, "shapegroup").value);
    }
    if (!group) xml.fail(n, "an instance needs a <ref id> to a shapegroup");
    Properties p = xml.properties(n, instance_plugin());
    InstanceDesc inst;
    inst.group = *group;
    reading([&] {
        if (const auto t = p.get_transform("to_world")) inst.to_world = *t;
        p.check_all_used();
        return 0;
    });
    // The group's exact spheres, placed here: a sphere stays a sphere under a rotation, a uniform
    // scale and a translation (Mitsuba 3 instances them the same way), and only then.
    static const std::vector<SphereDesc> kNone;
    const std::vector<SphereDesc>& spheres = *group < b.group_spheres.size() ? b.group_spheres[*group] : kNone;
    if (!spheres.empty()) {
        const Transform& t = inst.to_world;
        const Vec3d x = t.vector({1, 0, 0}), y = t.vector({0, 1, 0}), z = t.vector({0, 0, 1});
        const double s = length(x);
        const auto close = [&](double a) { return std::abs(a - s) <= 1e-5 * s; };
        if (!(s > 0) || !close(length(y)) || !close(length(z)) || std::abs(dot(x, y)) > 1e-5 * s * s || std::abs(dot(y, z)) > 1e-5 * s * s ||
            std::abs(dot(z, x)) > 1e-5 * s * s)
            xml.fail(n, "this shapegroup holds an exact sphere, which an instance can only rotate, scale uniformly and translate (a shear "
                        "or a non-uniform scale makes an ellipsoid): use a sphere mesh (obj, ply) in the group");
        for (SphereDesc sphere : spheres) {
            sphere.center = Vec3f(t.point(Vec3d(sphere.center)));
            sphere.radius = float(sphere.radius * s);
            for (Vec3f& a : sphere.axes) a = Vec3f(normalize(t.vector(Vec3d(a))));
            b.desc.spheres.push_back(sphere);
        }
    }
    if (!b.desc.groups[*group].meshes.empty()) b.desc.instances.push_back(inst);
}

}  // namespace

std::vector<PluginInfo> group_shape_plugins() { return {shapegroup_plugin(), instance_plugin()}; }

void read_shape(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b) { read_shape_into(xml, n, b, nullptr); }

namespace {

void read_shape_into(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b, std::vector<MeshDesc>* group,
                     std::vector<SphereDesc>* group_spheres) {
    xml.check_attributes(n, {"type", "id", "name"});
    const std::string type = xml.attr(n, "type");
    if (type == "shapegroup" && !group) return read_shapegroup(xml, n, b);
    if (type == "instance" && !group) return read_instance(xml, n, b);
    const ShapePlugin* plugin = find_shape_plugin(type);
    if (!plugin) {
        std::vector<std::string> names;
        for (const ShapePlugin& s : shape_plugins()) names.push_back(s.info().type);
        names.push_back("shapegroup");
        names.push_back("instance");
        xml.fail(n, fmt::format("unsupported shape type '{}'; supported: {}", type, fmt::join(names, ", ")));
    }

    std::optional<uint32_t> material;
    bool null_bsdf = false;
    MediumInterface media;
    Rgb emission(0.0f);
    std::shared_ptr<const EmissionSpectrum> emission_spectrum;
    std::shared_ptr<const Texture> emission_texture;  // <texture name="radiance"> in the emitter
    pugi::xml_node emitter_node;
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
        const std::string ref_name = tag == "ref" ? std::string(c.attribute("name").value()) : "";
        if (tag == "medium") {
            int32_t& slot = medium_side(c);
            slot = read_medium(xml, c, b);
        } else if (ref_name == "interior" || ref_name == "exterior") {
            int32_t& slot = medium_side(c);
            slot = medium_reference(xml, c, b);
        } else if (tag == "ref") {
            // A <ref> names its kind by what it refers to (a bsdf, an emitter, ...).
            xml.check_attributes(c, {"id", "name"});
            const std::string id = xml.attr(c, "id");
            const auto it = b.named.find(id);
            if (it == b.named.end()) xml.fail(c, fmt::format("no <bsdf> with id '{}' is declared before this reference", id));
            if (it->second.kind == "medium")
                xml.fail(c, fmt::format("'{}' is a medium: refer to it with name=\"interior\" or name=\"exterior\"", id));
            if (it->second.kind != "bsdf")
                xml.fail(c, fmt::format("'{}' is a <{}>; a shape refers to a <bsdf> (its emitter is nested: <emitter type=\"area\">)", id,
                                        it->second.kind));
            if (material || null_bsdf) xml.fail(c, "a shape can have only one BSDF");
            if (it->second.value.type() == typeid(NullBsdf))
                null_bsdf = true;
            else
                material = std::any_cast<uint32_t>(it->second.value);
        } else if (tag == "bsdf") {
            if (material || null_bsdf) xml.fail(c, "a shape can have only one BSDF");
            if (xml.optional_attr(c, "type") == null_bsdf_plugin().type) {
                xml.check_attributes(c, {"type", "name", "id"});
                if (!xml.plugin_children(c).empty()) xml.fail(xml.plugin_children(c).front(), "a null BSDF has no nested plugins");
                Properties np = xml.properties(c, null_bsdf_plugin());
                reading([&] { return np.check_all_used(), 0; });
                null_bsdf = true;
                if (const auto id = xml.optional_attr(c, "id")) b.name(xml, c, *id, "bsdf", NullBsdf{});
            } else {
                material = b.add_material(read_bsdf(xml, c, b));
                if (const auto id = xml.optional_attr(c, "id")) {
                    b.name(xml, c, *id, "bsdf", *material);
                    b.name_material(*material, *id);
                }
            }
        } else if (tag == "emitter") {
            xml.check_attributes(c, {"type", "id", "name"});
            const std::string etype = xml.attr(c, "type");
            if (etype != area_plugin().type) xml.fail(c, fmt::format("a shape's emitter must be of type 'area', not '{}'", etype));
            if (emitter) xml.fail(c, "a shape can have only one emitter");
            // Its radiance: a value, or a texture (Mitsuba 3's spatially varying area light).
            for (const pugi::xml_node& t : xml.plugin_children(c)) {
                const std::string t_tag = t.name();
                if ((t_tag != "texture" && t_tag != "ref") || std::string(t.attribute("name").value()) != "radiance")
                    xml.fail(t, "an area emitter's only nested plugin is its radiance: <texture name=\"radiance\" ...> (or a <ref "
                                "name=\"radiance\"> to one)");
                if (emission_texture) xml.fail(t, "an area emitter takes one radiance texture");
                emission_texture = texture_child(xml, t, b);
                if (std::holds_alternative<MeshAttributeTexture>(emission_texture->model()))
                    xml.fail(t, "an area emitter's radiance cannot be a mesh_attribute texture in pathlab (use a bitmap)");
            }
            Properties ep = xml.properties(c, area_plugin());
            if (emission_texture && ep.has("radiance")) xml.fail(c, "the emitter's radiance is given twice (a value and a texture)");
            emission = reading([&] {
                const Rgb L = emission_texture ? emission_texture->max_value() : read_area_radiance(ep);
                ep.check_all_used();
                return L;
            });
            emission_spectrum = emitter_spectrum(ep);
            emitter_node = c;
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
    ShapeContext files = b.shapes;
    if (files.allow_files) files.search_dirs = xml.search_dirs();
    ShapeDesc shape = reading([&] {
        ShapeDesc s = plugin->read(p, files);
        p.check_all_used();
        return s;
    });
    check_mesh_attributes(xml, n, b, *material, shape, group != nullptr);
    if (group) {
        if (emitter) xml.fail(n, "a shape in a shapegroup cannot emit light (pathlab samples emitters one by one)");
        if (media.changes_medium() || media.index_matched) xml.fail(n, "a shape in a shapegroup cannot bound media (place it on its own)");
    }
    if (emission_texture && (std::holds_alternative<SphereDesc>(shape) || std::get<MeshDesc>(shape).uv_map != UvMap::Vertices ||
                             std::get<MeshDesc>(shape).uvs.empty()))
        xml.fail(emitter_node, fmt::format("a textured area emitter needs a mesh with texture coordinates in pathlab (obj or ply with uv, "
                                           "serialized, rectangle, cube); this {} has {}",
                                           type, std::holds_alternative<SphereDesc>(shape) ? "an exact sphere's parameterisation"
                                                                                          : "none per vertex"));
    if (auto* sphere = std::get_if<SphereDesc>(&shape)) {
        sphere->material = *material;
        if (group) {  // in the group's space; each instance places a copy (read_instance)
            group_spheres->push_back(*sphere);
            return;
        }
        sphere->emission = emission;
        sphere->media = media;
        if (const auto id = xml.optional_attr(n, "id")) sphere->id = *id;
        b.desc.spheres.push_back(*sphere);
        if (emission_spectrum) {
            b.desc.sphere_emission_spectra.resize(b.desc.spheres.size());
            b.desc.sphere_emission_spectra.back() = emission_spectrum;
        }
        return;
    }
    MeshDesc& m = std::get<MeshDesc>(shape);
    if (m.name.empty()) m.name = type;
    if (const auto id = xml.optional_attr(n, "id")) m.name = m.id = *id;
    m.material = *material;
    m.emission = emission;
    m.media = media;
    (group ? *group : b.desc.meshes).push_back(std::move(m));
    if (emission_spectrum) {  // not in a group: a group's shapes cannot emit
        b.desc.mesh_emission_spectra.resize(b.desc.meshes.size());
        b.desc.mesh_emission_spectra.back() = emission_spectrum;
    }
    if (emission_texture) {
        b.desc.mesh_emission_textures.resize(b.desc.meshes.size());
        b.desc.mesh_emission_textures.back() = emission_texture;
    }
}

}  // namespace
}  // namespace pathlab
