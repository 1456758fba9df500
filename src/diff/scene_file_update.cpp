#include "diff/scene_file_update.hpp"

#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <variant>

#include <fmt/format.h>
#include <pugixml.hpp>

namespace pathlab {
namespace {

pugi::xml_node find_by_id(pugi::xml_node root, const char* tag, const std::string& id) {
    for (pugi::xml_node n : root.children()) {
        if (std::string(n.name()) == tag && id == n.attribute("id").value()) return n;
        if (pugi::xml_node inner = find_by_id(n, tag, id)) return inner;
    }
    return {};
}

// The XML parameter names (Mitsuba 3's, then the camelCase of 0.6) of a parameter.
std::vector<std::string> xml_names(const SceneParameter& p, const std::string& bsdf_type) {
    switch (p.field) {
        case ParamField::PhongDiffuse:
            return bsdf_type == "diffuse" ? std::vector<std::string>{"reflectance"}
                                          : std::vector<std::string>{"diffuse_reflectance", "diffuseReflectance"};
        case ParamField::PlasticDiffuse:
        case ParamField::RoughPlasticDiffuse: return {"diffuse_reflectance", "diffuseReflectance"};
        case ParamField::PhongExponent: return {"exponent"};
        case ParamField::RoughConductorAlpha:
        case ParamField::RoughDielectricAlpha:
        case ParamField::RoughPlasticAlpha: return {"alpha"};
        case ParamField::AlphaU: return {"alpha_u", "alphaU"};
        case ParamField::AlphaV: return {"alpha_v", "alphaV"};
        case ParamField::MeshRadiance:
        case ParamField::SphereRadiance:
        case ParamField::ConstantRadiance: return {"radiance"};
        case ParamField::PointIntensity: return {"intensity"};
        default: return {"specular_reflectance", "specularReflectance"};
    }
}

void set_value(pugi::xml_node element, const std::vector<std::string>& names, const std::vector<float>& v) {
    pugi::xml_node old;
    for (pugi::xml_node c : element.children())
        for (const std::string& n : names)
            if (n == c.attribute("name").value()) old = c;
    const std::string value = v.size() == 1 ? fmt::format("{}", v[0]) : fmt::format("{}, {}, {}", v[0], v[1], v[2]);
    pugi::xml_node fresh = old ? element.insert_child_before(v.size() == 1 ? "float" : "rgb", old)
                               : element.prepend_child(v.size() == 1 ? "float" : "rgb");
    fresh.append_attribute("name") = names.front().c_str();
    fresh.append_attribute("value") = value.c_str();
    if (old) element.remove_child(old);
}

// The bitmap <texture> giving parameter `names` of a BSDF element: nested, or the top-level one
// a <ref name="..." id="..."/> names.
pugi::xml_node texture_of(pugi::xml_node scene, pugi::xml_node bsdf, const std::vector<std::string>& names) {
    for (pugi::xml_node c : bsdf.children())
        for (const std::string& n : names) {
            if (n != c.attribute("name").value()) continue;
            if (std::string(c.name()) == "texture") return c;
            if (std::string(c.name()) == "ref") return find_by_id(scene, "texture", c.attribute("id").value());
        }
    return {};
}

void set_filename(pugi::xml_node texture, const std::string& file) {
    pugi::xml_node f = texture.find_child_by_attribute("string", "name", "filename");
    if (!f) {
        f = texture.prepend_child("string");
        f.append_attribute("name") = "filename";
        f.append_attribute("value");
    }
    f.attribute("value") = file.c_str();
}

}  // namespace

std::string scene_file_with_values(const std::string& scene_file, const ParameterSet& set, const std::vector<float>& theta,
                                   const std::map<std::string, std::string>& texel_files, const SceneDescription* with_values) {
    pugi::xml_document doc;
    const pugi::xml_parse_result r = doc.load_file(scene_file.c_str(), pugi::parse_default | pugi::parse_comments);
    if (!r) throw std::runtime_error(fmt::format("{}: cannot be read again: {}", scene_file, r.description()));
    pugi::xml_node scene = doc.child("scene");
    for (size_t i = 0; i < set.params.size(); ++i) {
        const SceneParameter& p = set.params[i];
        const std::string id = p.name.substr(0, p.name.find('.'));
        const std::vector<float> v(theta.begin() + set.offsets[i], theta.begin() + set.offsets[i] + p.size);
        pugi::xml_node element;
        std::string bsdf_type;
        if (p.is_material()) {
            element = find_by_id(scene, "bsdf", id);
            // Wrappers (twosided, normal and bump maps) hold the BSDF with the parameters.
            while (element && element.child("bsdf")) {
                const std::string type = element.attribute("type").value();
                if (type != "twosided" && type != "normalmap" && type != "bumpmap") break;
                element = element.child("bsdf");
            }
            if (element) bsdf_type = element.attribute("type").value();
        } else if (p.is_medium()) {
            element = find_by_id(scene, "medium", id);
        } else if (p.field == ParamField::MeshRadiance || p.field == ParamField::SphereRadiance) {
            element = find_by_id(scene, "shape", id);
            if (element) element = element.child("emitter");
        } else {
            element = find_by_id(scene, "emitter", id);
        }
        if (!element)
            throw std::runtime_error(fmt::format("{}: the element of parameter {} (id '{}') is not in this file (an <include>d one?); "
                                                 "its value is in the JSON output",
                                                 scene_file, p.name, id));
        if (p.is_texels()) {
            SceneParameter of = p;
            of.field = p.texels_of;
            const pugi::xml_node texture = texture_of(scene, element, xml_names(of, bsdf_type));
            const auto file = texel_files.find(p.name);
            if (!texture || file == texel_files.end())
                throw std::runtime_error(fmt::format("{}: the bitmap <texture> of parameter {} is not in this file; its texels are in the "
                                                     "JSON output", scene_file, p.name));
            set_filename(texture, file->second);
            continue;
        }
        if (p.field == ParamField::MediumPhaseG) {
            const pugi::xml_node phase = element.child("phase");
            if (!phase)
                throw std::runtime_error(fmt::format("{}: the <phase> of parameter {} is not in this file; its value is in the JSON output",
                                                     scene_file, p.name));
            set_value(phase, {"g"}, v);
            continue;
        }
        if (p.is_medium()) {  // sigma_t and albedo together, in place of sigma_a, sigma_s and scale
            if (!with_values) throw std::logic_error("scene_file_with_values: a medium's parameters need the description with their values");
            const auto& m = std::get<HomogeneousMedium>(with_values->media.at(p.index));
            Rgb albedo(0.0f);
            for (int c = 0; c < 3; ++c) albedo[c] = m.sigma_t[c] > 0 ? m.sigma_s[c] / m.sigma_t[c] : 0.0f;
            for (const char* n : {"sigma_a", "sigmaA", "sigma_s", "sigmaS", "scale"})
                while (pugi::xml_node c = element.find_child_by_attribute("name", n)) element.remove_child(c);
            set_value(element, {"albedo"}, {albedo.x, albedo.y, albedo.z});
            set_value(element, {"sigma_t", "sigmaT"}, {m.sigma_t.x, m.sigma_t.y, m.sigma_t.z});
            continue;
        }
        if (p.field == ParamField::RoughDielectricEta) {  // only the ratio matters: int_ior = eta, ext_ior = 1
            set_value(element, {"int_ior", "intIOR"}, v);
            set_value(element, {"ext_ior", "extIOR"}, {1.0f});
            continue;
        }
        set_value(element, xml_names(p, bsdf_type), v);
        if (xml_names(p, bsdf_type).front() == "alpha")  // a file's equal alpha_u and alpha_v were one alpha: now given as alpha
            for (const char* n : {"alpha_u", "alphaU", "alpha_v", "alphaV"})
                if (pugi::xml_node c = element.find_child_by_attribute("name", n)) element.remove_child(c);
    }
    // Files the scene names are found from the original folder.
    const std::string dir = std::filesystem::absolute(std::filesystem::path(scene_file)).parent_path().string();
    pugi::xml_node path = scene.prepend_child("path");
    path.append_attribute("value") = dir.c_str();
    scene.insert_child_before(pugi::node_comment, path)
        .set_value(" written by pathlab optimize: the original scene with the optimised parameters; meshes from its folder ");
    std::ostringstream out;
    doc.save(out, "    ");
    return out.str();
}

}  // namespace pathlab
