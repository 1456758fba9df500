// Materials (BSDFs). A closed set of types dispatched with std::visit in the hot loop.
//
// Conventions, stated once for every material:
//  - Directions are unit vectors in the local shading frame (normal = +z), and both point
//    away from the surface: `wi` towards where the path came from (the camera side for camera
//    paths, the light side for light paths), `wo` the other direction (towards a light or the
//    camera, or the sampled continuation).
//  - eval(wi, wo) returns the BSDF value f (no cosine factor).
//  - pdf(wi, wo) and BsdfSample::pdfW are densities per unit solid angle of wo.
//  - sample(wi, u) draws wo given two uniform numbers in [0,1).
// The models (one header each) compute radiance-mode values. Material's functions that take a
// BsdfContext apply the transport mode (bsdf_context.hpp), fill the reverse pdf and evaluate
// the material's textures at the context's uv (material_textures.hpp); the ones without a
// context are the plain radiance-mode models (of a textured material: the model of its
// textures' largest values, which only its lobe flags and is_black() use).
//
// Normal and bump maps tilt the shading frame (make_shading_point builds it with
// shading_frame()); it is then a shading normal like an interpolated vertex normal, with one
// addition: directions on different sides of the geometric and the perturbed shading surface
// are refused in radiance mode too (importance mode refuses them for every shading normal), so
// that both modes see the same BSDF and bidirectional methods agree with path tracing.
#pragma once

#include <memory>
#include <optional>
#include <variant>
#include <string>
#include <vector>

#include "bsdfs/bsdf_context.hpp"
#include "bsdfs/conductor.hpp"
#include "bsdfs/ior.hpp"
#include "bsdfs/dielectric.hpp"
#include "bsdfs/material_textures.hpp"
#include "bsdfs/phong.hpp"
#include "bsdfs/plastic.hpp"
#include "bsdfs/principled.hpp"
#include "bsdfs/principledthin.hpp"
#include "bsdfs/roughconductor.hpp"
#include "bsdfs/roughdielectric.hpp"
#include "bsdfs/roughplastic.hpp"
#include "bsdfs/thindielectric.hpp"
#include "spectral/dense_spectrum.hpp"

namespace pathlab {

struct Material;

// blendbsdf: (1 - weight) * first + weight * second (Mitsuba's blendbsdf; the weight may be a
// texture). Sampling picks a BSDF with probability 1 - weight or weight; eval and pdf mix both
// (their non-delta lobes), a delta sample keeps its own coefficient times the choice's
// probability (bsdf_sample.hpp). Textured nested BSDFs are evaluated at `uv`, which
// Material::model_at sets (normal and bump maps inside a blend are refused: the blend has one
// shading frame; wrap the blend instead).
struct BlendMaterial {
    std::shared_ptr<const Material> first, second;
    float weight = 0.5f;  // of `second`
    SurfaceUv uv = {};  // where the nested BSDFs are evaluated (textured ones only)

    static constexpr int kSlotWeight = 0;
    void set_texel(int, const Rgb& v) { weight = v.x; }
    void set_uv(const SurfaceUv& at) { uv = at; }

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const;
    float pdf(const Vec3f& wi, const Vec3f& wo) const;
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const;
};

// mask: opacity * the nested BSDF, and with probability 1 - opacity the path goes straight
// through (a Dirac delta along -wi of coefficient 1 - opacity, on either side). The opacity may
// be a texture (cut-outs); a textured nested BSDF is evaluated at `uv`, as in BlendMaterial.
struct MaskMaterial {
    std::shared_ptr<const Material> inner;
    float opacity = 0.5f;
    SurfaceUv uv = {};

    static constexpr int kSlotOpacity = 0;
    void set_texel(int, const Rgb& v) { opacity = v.x; }
    void set_uv(const SurfaceUv& at) { uv = at; }

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const;
    float pdf(const Vec3f& wi, const Vec3f& wo) const;
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const;
};

// One BSDF per header (parameters and defaults documented at the top of each).
using MaterialModel = std::variant<PhongMaterial, ConductorMaterial, DielectricMaterial, RoughConductorMaterial,
                                   RoughDielectricMaterial, PlasticMaterial, RoughPlasticMaterial, ThinDielectricMaterial,
                                   BlendMaterial, MaskMaterial, PrincipledMaterial, PrincipledThinMaterial>;

// std::visit, as a switch that the compiler always inlines: the hot loop calls sample() at
// several places, and an out-of-line dispatch there cost about 3% of pt-mis's time.
template <typename F>
[[gnu::always_inline]] inline decltype(auto) visit_model(const MaterialModel& model, F&& f) {
    static_assert(std::variant_size_v<MaterialModel> == 12, "add the new model's case below");
    switch (model.index()) {
        case 0: return f(*std::get_if<0>(&model));
        case 1: return f(*std::get_if<1>(&model));
        case 2: return f(*std::get_if<2>(&model));
        case 3: return f(*std::get_if<3>(&model));
        case 4: return f(*std::get_if<4>(&model));
        case 5: return f(*std::get_if<5>(&model));
        case 6: return f(*std::get_if<6>(&model));
        case 7: return f(*std::get_if<7>(&model));
        case 8: return f(*std::get_if<8>(&model));
        case 9: return f(*std::get_if<9>(&model));
        case 10: return f(*std::get_if<10>(&model));
        default: return f(*std::get_if<11>(&model));
    }
}

// Reflectances a scene file gave as spectra (`wavelength:value` pairs or a file), which spectral
// mode uses instead of upsampling their RGB conversion (docs/spectral.md): the model's diffuse
// reflectance (diffuse's and plastic's, Phong's rho_d) and its specular one (Phong's rho_s, a
// conductor's or plastic's specular_reflectance); null where the file gave an RGB value.
struct MaterialSpectra {
    std::shared_ptr<const DenseSpectrum> diffuse, specular;
};

struct Material {
    MaterialModel model;
    // Two-sided materials shade the back of a surface like its front (the frame is flipped
    // to face the incoming direction); one-sided ones are black from behind. A dielectric
    // is neither: both of its sides are meaningful, and its frame is never flipped.
    bool two_sided = true;
    // twosided with two BSDFs: the index (in the scene's materials) of the one for the back,
    // used with the frame flipped as for the front; -1: the same material on both sides.
    int32_t back = -1;
    // Set by set_textures() and prepare() (Scene::build calls it), read at every hit:
    bool varies = false;               // it has textures, a normal or a bump map
    bool tangent_frame = false;        // its shading frame follows dp/du (anisotropic, normal or bump mapped)
    bool surface_coordinates = false;  // either: it uses uv, dp/du and dp/dv
    std::shared_ptr<const MaterialTextures> textures = nullptr;  // null: the same everywhere
    // Spectral mode's reflectances given in the scene file as spectra (null: none; RGB mode uses
    // the model's RGB colours, their conversions).
    std::shared_ptr<const MaterialSpectra> spectra = nullptr;

    // Binds textures (and a normal or bump map) to the material.
    void set_textures(MaterialTextures t) {
        textures = std::make_shared<const MaterialTextures>(std::move(t));
        prepare();
    }
    // Computes the three flags above from the model, the textures and, for blendbsdf and mask,
    // the nested materials.
    void prepare();
    bool perturbed() const { return textures && textures->perturbation != FramePerturbation::None; }
    // A normal or bump map with Mitsuba's non-reciprocal options (material_textures.hpp).
    bool flips_invalid_normals() const { return perturbed() && textures->flip_invalid_normals; }
    bool mitsuba_bump_rules() const { return perturbed() && (textures->flip_invalid_normals || textures->shadowing_function); }
    // The model at surface coordinates uv: the textured parameters set to their values there.
    MaterialModel model_at(const SurfaceUv& uv) const;
    // The shading frame at a hit whose front-side unit shading and geometric normals are n, ng
    // (for tangent_frame materials; the others use Frame(n)): tangent_frame() or
    // perturbed_frame() of material_textures.hpp, reversed (n -> -n) for the back of a
    // two-sided material, which is the same tilted surface seen from behind.
    Frame shading_frame(const Vec3f& n, const Vec3f& ng, bool back, const Vec3f& dpdu, const Vec3f& dpdv, const SurfaceUv& uv) const;

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const {
        return visit_model(model, [&](const auto& m) { return m.eval(wi, wo); });
    }
    float pdf(const Vec3f& wi, const Vec3f& wo) const {
        return visit_model(model, [&](const auto& m) { return m.pdf(wi, wo); });
    }
    // eval() and pdf() together, for models that can share work between them.
    Rgb eval_and_pdf(const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        return visit_model(model, [&](const auto& m) {
            if constexpr (requires { m.eval_and_pdf(wi, wo, pdf); }) {
                return m.eval_and_pdf(wi, wo, pdf);
            } else {
                pdf = m.pdf(wi, wo);
                return m.eval(wi, wo);
            }
        });
    }
    [[gnu::always_inline]] std::optional<BsdfSample> sample(const Vec3f& wi, const Vec2f& u) const {
        return visit_model(model, [&](const auto& m) { return m.sample(wi, u); });
    }
    // ---- with a shading context (transport mode, reverse pdf, uv) ------------------------
    // Radiance mode without a reverse pdf, of a material that does not vary, is the plain
    // model and stays inline (the path tracers' hot loop); the rest takes the out-of-line
    // adjusted path.
    Rgb eval(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const {
        if (!varies) [[likely]] {
            if (ctx.mode == TransportMode::Radiance) [[likely]]
                return eval(wi, wo);
            return eval(wi, wo) * importance_factor(ctx, wi, wo);
        }
        return eval_varying(ctx, wi, wo);
    }
    float pdf(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const {
        if (!varies) [[likely]]
            return pdf(wi, wo);
        return pdf_varying(ctx, wi, wo);
    }
    Rgb eval_and_pdf(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        if (!varies) [[likely]] {
            if (ctx.mode == TransportMode::Radiance) [[likely]]
                return eval_and_pdf(wi, wo, pdf);
            return eval_and_pdf(wi, wo, pdf) * importance_factor(ctx, wi, wo);
        }
        return eval_and_pdf_varying(ctx, wi, wo, pdf);
    }
    [[gnu::always_inline]] std::optional<BsdfSample> sample(const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u) const {
        if (ctx.mode == TransportMode::Radiance && !ctx.reverse_pdf && !varies) [[likely]]
            return sample(wi, u);
        return sample_adjusted(ctx, wi, u);
    }
    // The fraction of light that passes straight through at surface coordinates uv, arriving at
    // |cos| = cos_i to the shading normal: the weight of its kLobeNull lobe (thindielectric's
    // 1 - R', a mask's 1 - opacity, mixed through blends); what a shadow ray carries through it
    // under --null-depth skip (Mitsuba's eval_null_transmission). 0 without such a lobe.
    float null_transmission(const SurfaceUv& uv, float cos_i) const;
    // The flags of every lobe the material has (BsdfLobe).
    uint32_t lobes() const {
        return std::visit([](const auto& m) { return lobes_of(m); }, model);
    }

    // True when the material reflects nothing (pure emitters): estimators stop there.
    bool is_black() const {
        if (const auto* p = std::get_if<PhongMaterial>(&model))
            return pathlab::is_black(p->diffuse) && pathlab::is_black(p->specular);
        return false;
    }
    // True when every lobe is a Dirac delta: light sampling cannot contribute there (eval()
    // is zero everywhere). Materials that mix delta and non-delta lobes (plastic) are not.
    bool is_delta() const {
        if (const auto* b = std::get_if<BlendMaterial>(&model)) return b->first->is_delta() && b->second->is_delta();
        if (const auto* m = std::get_if<MaskMaterial>(&model)) return m->inner->is_delta();
        return std::holds_alternative<ConductorMaterial>(model) || std::holds_alternative<DielectricMaterial>(model) ||
               std::holds_alternative<ThinDielectricMaterial>(model);
    }
    // True for materials that transmit (both sides matter: never flipped, never twosided).
    bool is_dielectric() const {
        if (const auto* p = std::get_if<PrincipledMaterial>(&model)) return p->transmits;
        return std::holds_alternative<DielectricMaterial>(model) || std::holds_alternative<RoughDielectricMaterial>(model);
    }
    // True where light from behind the surface may reach the other side through a lobe light
    // sampling can see: rough glass, and thin sheets (two-sided, no inside), also within a blend
    // or mask. Next-event estimation skips lights behind other surfaces.
    bool transmits() const {
        if (std::holds_alternative<PrincipledThinMaterial>(model)) return true;
        if (std::holds_alternative<BlendMaterial>(model) || std::holds_alternative<MaskMaterial>(model))
            return (lobes() & kLobeTransmission) != 0;
        return is_dielectric();
    }

    // The mesh attributes its textures read (mesh_attribute), nested materials included, each
    // with whether a float parameter reads it (one channel needed): what a shape must have.
    struct AttributeUse {
        std::string name;
        bool scalar = false;
    };
    std::vector<AttributeUse> mesh_attributes_read() const;

    // The context's adjustments (material.cpp: out of line, so that the hot path's visit of the
    // model stays the only one in the integrators' code and is inlined there).
    std::optional<BsdfSample> sample_adjusted(const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u) const;
    Rgb eval_varying(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const;
    float pdf_varying(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const;
    Rgb eval_and_pdf_varying(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, float& pdf) const;

    // What importance transport multiplies the radiance-mode BSDF by (bsdf_context.hpp): the
    // refraction factor (eta_wo / eta_wi)^2 and the shading-normal correction; 0 for directions
    // on different sides of the geometric and the shading surface.
    float importance_factor(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const;
    // What radiance mode multiplies a normal- or bump-mapped BSDF by: 0 for directions the map
    // puts on the wrong side, and Mitsuba's shadowing term (material_textures.hpp).
    float perturbation_factor(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const;

private:
    // What the context multiplies a varying material's radiance-mode BSDF by: importance mode's
    // factor, or for a perturbed frame in radiance mode 0 where wi or wo lie on different sides
    // of the geometric and the shading surface (1 elsewhere).
    float context_factor(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const;

    static uint32_t lobes_of(const PhongMaterial& m) {
        return kLobeReflection | (pathlab::is_black(m.diffuse) ? 0u : kLobeDiffuse) | (pathlab::is_black(m.specular) ? 0u : kLobeGlossy);
    }
    static uint32_t lobes_of(const ConductorMaterial&) { return kLobeSpecular | kLobeReflection; }
    static uint32_t lobes_of(const DielectricMaterial&) { return kLobeSpecular | kLobeReflection | kLobeTransmission; }
    static uint32_t lobes_of(const RoughConductorMaterial&) { return kLobeGlossy | kLobeReflection; }
    static uint32_t lobes_of(const RoughDielectricMaterial&) { return kLobeGlossy | kLobeReflection | kLobeTransmission; }
    static uint32_t lobes_of(const PlasticMaterial&) { return kLobeDiffuse | kLobeSpecular | kLobeReflection; }
    static uint32_t lobes_of(const RoughPlasticMaterial&) { return kLobeDiffuse | kLobeGlossy | kLobeReflection; }
    static uint32_t lobes_of(const ThinDielectricMaterial&) { return kLobeSpecular | kLobeReflection | kLobeTransmission | kLobeNull; }
    static uint32_t lobes_of(const BlendMaterial& m) { return m.first->lobes() | m.second->lobes(); }
    static uint32_t lobes_of(const MaskMaterial& m) { return m.inner->lobes() | kLobeSpecular | kLobeTransmission | kLobeNull; }
    static uint32_t lobes_of(const PrincipledMaterial& m) {
        return kLobeDiffuse | kLobeGlossy | kLobeReflection | (m.transmits ? kLobeTransmission : 0u);
    }
    static uint32_t lobes_of(const PrincipledThinMaterial& m) {
        return kLobeDiffuse | kLobeReflection | (m.spec_trans > 0 ? kLobeGlossy : 0u) | (m.spec_trans > 0 || m.diff_trans > 0 ? kLobeTransmission : 0u);
    }
};

// The diffuse reflectance (Mitsuba's aov "albedo"): Lambertian and Phong's rho_d, a coated
// base's rho, mixtures of them; 0 for purely glossy or specular materials.
inline Rgb diffuse_albedo(const Material& m) {
    if (const auto* p = std::get_if<PhongMaterial>(&m.model)) return p->diffuse;
    if (const auto* p = std::get_if<PlasticMaterial>(&m.model)) return p->coat.diffuse_reflectance;
    if (const auto* p = std::get_if<RoughPlasticMaterial>(&m.model)) return p->coat.diffuse_reflectance;
    if (const auto* p = std::get_if<PrincipledMaterial>(&m.model)) return p->base_color;  // as Mitsuba's eval_diffuse_reflectance
    if (const auto* p = std::get_if<PrincipledThinMaterial>(&m.model)) return p->base_color;
    if (const auto* b = std::get_if<BlendMaterial>(&m.model))
        return diffuse_albedo(*b->first) * (1 - b->weight) + diffuse_albedo(*b->second) * b->weight;
    if (const auto* k = std::get_if<MaskMaterial>(&m.model)) return diffuse_albedo(*k->inner) * k->opacity;
    return Rgb(0.0f);
}

inline Material make_phong(const Rgb& diffuse, const Rgb& specular = Rgb(0.0f), float exponent = 1) {
    return Material{PhongMaterial{diffuse, specular, exponent}};
}
// A perfect mirror (conductor with material="none") scaled by `reflectance`.
inline Material make_mirror(const Rgb& reflectance = Rgb(1.0f)) {
    return Material{ConductorMaterial{Rgb(0.0f), Rgb(1.0f), reflectance}};
}
inline Material make_conductor(const ComplexIor& ior, const Rgb& reflectance = Rgb(1.0f)) {
    return Material{ConductorMaterial{ior.eta, ior.k, reflectance, ior.measured}};
}
inline Material make_rough_conductor(const MicrofacetDistribution& d, const ComplexIor& ior = {Rgb(0.0f), Rgb(1.0f)},
                                     const Rgb& reflectance = Rgb(1.0f)) {
    return Material{RoughConductorMaterial{d, ior.eta, ior.k, reflectance, ior.measured}};
}
inline Material make_dielectric(float int_ior, float ext_ior = 1.000277f) {
    return Material{DielectricMaterial{int_ior, ext_ior}, false};
}
inline Material make_rough_dielectric(const MicrofacetDistribution& d, float int_ior, float ext_ior = 1.000277f) {
    return Material{RoughDielectricMaterial{d, int_ior, ext_ior}, false};
}
inline Material make_plastic(const Rgb& diffuse, const Rgb& specular = Rgb(1.0f), float int_ior = 1.49f,
                             float ext_ior = 1.000277f, bool nonlinear = false) {
    return Material{PlasticMaterial{CoatedDiffuse(diffuse, specular, int_ior, ext_ior, nonlinear)}};
}
inline Material make_rough_plastic(const MicrofacetDistribution& d, const Rgb& diffuse, const Rgb& specular = Rgb(1.0f),
                                   float int_ior = 1.49f, float ext_ior = 1.000277f, bool nonlinear = false) {
    return Material{RoughPlasticMaterial{d, CoatedDiffuse(diffuse, specular, int_ior, ext_ior, nonlinear)}};
}

}  // namespace pathlab
