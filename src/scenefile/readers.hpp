// One reader per element kind of a scene file (scene_file.cpp dispatches to them). Each looks
// its plugin up by type in the registry of its layer and reads the element's properties
// through the plugin's declared parameters.
#pragma once

#include <any>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "geometry/shape_plugins.hpp"
#include "scene/scene_description.hpp"
#include "scenefile/xml_source.hpp"

namespace pathlab {

// An object declared with an id, for <ref id> and <alias>: its kind (the element's name: bsdf,
// emitter, shape, texture, medium, ...) and what its reader made of it (a BSDF: the uint32_t
// index of its material). Readers of other kinds (textures, media) add theirs the same way.
struct NamedObject {
    std::string kind;
    SourceLocation where;
    std::any value;
};

// The value of a <bsdf type="null" id="..."> in SceneBuilder::named (kind "bsdf"): no material,
// only the mark that makes a shape an index-matched boundary between its media. Named media are
// kind "medium" with their int32_t index into desc.media.
struct NullBsdf {};

// What the readers build up while a file is read.
struct SceneBuilder {
    SceneDescription desc;
    std::map<std::string, NamedObject> named;  // by id
    std::optional<uint32_t> default_material;
    bool have_sensor = false, have_integrator = false;
    ShapeContext shapes;
    // The exact spheres of each shapegroup (by its index in desc.groups): Embree instances
    // only the meshes, so each instance places its own copies of the spheres (read_shape.cpp).
    std::vector<std::vector<SphereDesc>> group_spheres;

    uint32_t add_material(const Material& m) {
        desc.materials.push_back(m);
        return uint32_t(desc.materials.size() - 1);
    }
    // Records `id` as the name of material `index` (SceneDescription::material_ids).
    void name_material(uint32_t index, const std::string& id) {
        if (desc.material_ids.size() <= index) desc.material_ids.resize(index + 1);
        desc.material_ids[index] = id;
    }
    // Declares `id` (an error at n if it is taken).
    void name(const XmlSource& xml, const pugi::xml_node& n, const std::string& id, const std::string& kind, std::any value);
    // The object a <ref id> names, which must be of kind `expected` (the error lists what the id is).
    const NamedObject& resolve(const XmlSource& xml, const pugi::xml_node& ref, const std::string& expected) const;
};

void read_integrator(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);  // read_integrator.cpp
// moment and aov (their PluginInfo, for the plugin reference).
std::vector<PluginInfo> integrator_wrapper_plugins();
// "a, b c" -> {"a", "b", "c"} (commas and spaces separate).
std::vector<std::string> split_list(const std::string& text);
void read_sensor(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);      // read_sensor.cpp (film, sampler)
// The camera and film of a file without a <sensor>: the plugins' defaults.
void use_default_sensor(SceneBuilder& b);
// A <bsdf> element, or a <ref> to one (nested BSDFs of twosided, blendbsdf, mask may be refs).
Material read_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);   // read_bsdf.cpp
void read_named_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);
std::shared_ptr<const Texture> read_texture(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);  // read_texture.cpp
void read_named_texture(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);
// A <texture> child, or a <ref> to a declared texture (read_texture.cpp).
std::shared_ptr<const Texture> texture_child(XmlSource& xml, const pugi::xml_node& c, SceneBuilder& b);
void read_shape(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);       // read_shape.cpp
std::vector<PluginInfo> group_shape_plugins();  // shapegroup, instance
void read_free_emitter(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);  // read_emitter.cpp
// The spectrum the plugin's parameter `name` was given as (a black body, a tabulated spectrum:
// Properties::Value::spectrum); null where it was not declared, not given or given as RGB.
std::shared_ptr<const SampledSpectrum> given_spectrum(Properties& p, const char* name);
// The spectrum an emitter's radiance, intensity or irradiance was given as, with the RGB the
// emitter read from it; null for an RGB value.
std::shared_ptr<const EmissionSpectrum> emitter_spectrum(Properties& p);
// read_medium.cpp: a <medium> (its index in desc.media), one declared at the top level, the
// medium a <ref id> names, and the null BSDF's declaration.
int32_t read_medium(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);
void read_named_medium(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);
int32_t medium_reference(XmlSource& xml, const pugi::xml_node& ref, const SceneBuilder& b);
const PluginInfo& null_bsdf_plugin();

}  // namespace pathlab
