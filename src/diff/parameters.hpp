// Differentiable scene parameters by name, as Mitsuba 3's traverse() names them:
//   <bsdf id>.reflectance.value             diffuse (Phong without a glossy lobe): rho, rgb
//   <bsdf id>.diffuse_reflectance.value     phong, plastic, roughplastic: rho_d, rgb
//   <bsdf id>.specular_reflectance.value    phong (rho_s), conductor, roughconductor, plastic, roughplastic: rgb
//   <bsdf id>.exponent                      phong: n, float
//   <bsdf id>.alpha                         roughconductor, roughdielectric (isotropic), roughplastic: roughness, float
//   <bsdf id>.alpha_u, <bsdf id>.alpha_v    roughconductor, roughdielectric (anisotropic): roughness along u, v, float
//   <bsdf id>.eta                           roughdielectric (not dispersive): int_ior / ext_ior, float
//   <shape id>.emitter.radiance.value       area emitter on a shape: radiance, rgb
//   <emitter id>.intensity.value            point light: intensity, rgb
//   <emitter id>.radiance.value             constant environment: radiance, rgb
//   <medium id>.sigma_t.value               homogeneous medium: extinction per unit length, rgb
//   <medium id>.albedo.value                homogeneous medium: sigma_s / sigma_t, rgb
//   <medium id>.phase_function.g            a medium's Henyey-Greenstein phase function: g, float
//   <bsdf id>.<reflectance>.data            a bitmap texture's texels in place of one of the rgb
//                                           reflectances above (e.g. reflectance.data): width *
//                                           height * 3 linear values, row-major, top row first
// A twosided wrapper is transparent (its id names the BSDF inside). Materials without an id,
// pure emitters' black BSDFs (paths end there) and the other models (smooth dielectrics: only an
// index of refraction, which moves refracted directions; blendbsdf, mask) have none; geometric
// parameters (vertex positions, transforms) are out of scope (docs/differentiable.md).
//
// A parameter is a view into a SceneDescription: get/set read and write its floats there, and
// the optimiser rebuilds the Scene from the changed description.
#pragma once

#include <string>
#include <vector>

#include "scene/scene_description.hpp"

namespace pathlab {

enum class ParamField {
    PhongDiffuse,
    PhongSpecular,
    PhongExponent,
    ConductorSpecular,
    RoughConductorSpecular,
    RoughConductorAlpha,
    PlasticDiffuse,
    PlasticSpecular,
    RoughPlasticDiffuse,
    RoughPlasticSpecular,
    RoughDielectricAlpha,
    RoughDielectricEta,
    RoughPlasticAlpha,
    AlphaU,  // an anisotropic roughconductor's or roughdielectric's alpha_u
    AlphaV,  // and alpha_v
    Texels,          // a bitmap texture's texels; SceneParameter::texels_of says which reflectance
    MeshRadiance,    // index: the mesh
    SphereRadiance,  // index: the sphere
    PointIntensity,  // index: the light in SceneDescription::lights
    ConstantRadiance,
    MediumSigmaT,  // index: the medium
    MediumAlbedo,
    MediumPhaseG,
};

struct SceneParameter {
    std::string name;   // e.g. "red.reflectance.value"
    ParamField field;
    uint32_t index = 0;  // material, mesh, sphere or free light, by field
    int size = 3;        // 3 (rgb) or 1 (float); width * height * 3 for texels
    // Texels: the reflectance the texture gives (one of the rgb fields above), the texture's
    // binding in the material (Material::textures->bindings) and its size.
    ParamField texels_of = ParamField::PhongDiffuse;
    int binding = -1;
    int width = 0, height = 0;

    bool is_material() const { return field < ParamField::MeshRadiance; }
    bool is_texels() const { return field == ParamField::Texels; }
    bool is_medium() const { return field >= ParamField::MediumSigmaT; }
    // "bsdf", "texture", "emitter" or "medium".
    std::string kind() const { return is_texels() ? "texture" : is_material() ? "bsdf" : is_medium() ? "medium" : "emitter"; }
    // The valid range, as the optimiser clamps to it ("[0, 1]", "> 0", ">= 0").
    std::string range() const;
};

// Every differentiable parameter of the scene, in a stable order (materials by index, then
// meshes, spheres and free lights). A reflectance given by a bitmap texture is listed as its
// texels (`.data`), once for a texture that several materials share (at the first); other
// textured parameters (checkerboards, scalar textures of an exponent or a roughness) are not
// differentiable and not listed, nor is a bitmap that is also used where no derivative flows
// (a scalar parameter, a normal or bump map, a BSDF inside blendbsdf or mask).
std::vector<SceneParameter> scene_parameters(const SceneDescription& d);

// The parameter named `name`; a std::invalid_argument listing the valid names otherwise.
const SceneParameter& find_parameter(const std::vector<SceneParameter>& all, const std::string& name);

std::vector<float> parameter_value(const SceneDescription& d, const SceneParameter& p);
// Writes `value` (p.size floats) into the description (rebuilding what a model precomputes;
// texels: a new texture, given to every material that shared the old one).
void set_parameter_value(SceneDescription& d, const SceneParameter& p, const std::vector<float>& value);
// Clamps to the valid range: reflectances to [0, 1], roughness to [1e-3, 10], the Phong
// exponent to [0, 10^4], emission to >= 1e-6 (a zero emitter would vanish from the scene).
void clamp_parameter_value(const SceneParameter& p, std::vector<float>& value);

// A set of chosen parameters laid out in one vector theta (each at its offset), and how the
// path replay finds them: per material and per light of a built Scene, the offsets (-1: not chosen).
// A reflectance given by texels: the offset of the texels (3 per texel) in theta and the
// binding in the material's textures whose lookup (Texture::footprint) says which texels a hit
// reads, with which weights.
struct TexelBinding {
    int offset = -1;
    int binding = -1;
    bool bound() const { return offset >= 0; }
};
struct MaterialBinding {
    int diffuse = -1, specular = -1, exponent = -1, alpha = -1, alpha_u = -1, alpha_v = -1, eta = -1;
    TexelBinding diffuse_texels, specular_texels;  // in place of diffuse, specular
    bool texels() const { return diffuse_texels.bound() || specular_texels.bound(); }
    bool any() const {
        return diffuse >= 0 || specular >= 0 || exponent >= 0 || alpha >= 0 || alpha_u >= 0 || alpha_v >= 0 || eta >= 0 || texels();
    }
};
// A homogeneous medium's offsets (-1: not chosen), and its slot among the chosen media (the path
// replay keeps d log(throughput) per slot).
struct MediumBinding {
    int sigma_t = -1, albedo = -1, g = -1;
    int slot = -1;
};
inline constexpr int kMaxDiffMedia = 8;  // media with chosen parameters, at most

struct ParameterSet {
    std::vector<SceneParameter> params;
    std::vector<int> offsets;  // of params[i] in theta
    int size = 0;              // floats in theta

    std::vector<MaterialBinding> materials;  // by material index
    // By index in Scene::lights(), in Scene::build's order (free lights, then each emitting
    // mesh's triangles, then emitting spheres): the offset of the light's radiance/intensity.
    std::vector<int> lights;
    std::vector<MediumBinding> media;  // by medium index
    int media_slots = 0;

    // Chooses `names` of the description's parameters (std::invalid_argument for an unknown
    // or repeated name, listing the valid ones, and for more than kMaxDiffMedia media).
    static ParameterSet choose(const SceneDescription& d, const std::vector<std::string>& names);

    std::vector<float> values(const SceneDescription& d) const;
    void set_values(SceneDescription& d, const std::vector<float>& theta) const;
    void clamp(std::vector<float>& theta) const;
};

}  // namespace pathlab
