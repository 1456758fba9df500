// One reader per element kind of a scene file (scene_file.cpp dispatches to them). Each looks
// its plugin up by type in the registry of its layer and reads the element's properties
// through the plugin's declared parameters.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "geometry/shape_plugins.hpp"
#include "scene/scene_description.hpp"
#include "scenefile/xml_source.hpp"

namespace pathlab {

// What the readers build up while a file is read.
struct SceneBuilder {
    SceneDescription desc;
    std::map<std::string, uint32_t> named_bsdfs;  // id -> index into desc.materials
    std::map<std::string, std::shared_ptr<const Texture>> named_textures;  // id -> texture
    std::optional<uint32_t> default_material;
    bool have_sensor = false, have_integrator = false;
    ShapeContext shapes;

    uint32_t add_material(const Material& m) {
        desc.materials.push_back(m);
        return uint32_t(desc.materials.size() - 1);
    }
    // BSDFs and textures share one namespace of ids.
    void check_new_id(const XmlSource& xml, const pugi::xml_node& n, const std::string& id) const {
        if (named_bsdfs.count(id) || named_textures.count(id)) xml.fail(n, "the id '" + id + "' is already used");
    }
};

void read_integrator(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);  // read_integrator.cpp
void read_sensor(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);      // read_sensor.cpp (film, sampler)
// The camera and film of a file without a <sensor>: the plugins' defaults.
void use_default_sensor(SceneBuilder& b);
Material read_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);     // read_bsdf.cpp
void read_named_bsdf(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);
std::shared_ptr<const Texture> read_texture(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);  // read_texture.cpp
void read_named_texture(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);
void read_shape(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);       // read_shape.cpp
void read_free_emitter(XmlSource& xml, const pugi::xml_node& n, SceneBuilder& b);  // read_emitter.cpp

}  // namespace pathlab
