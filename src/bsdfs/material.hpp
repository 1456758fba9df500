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
// BsdfContext apply the transport mode (bsdf_context.hpp) and fill the reverse pdf; the ones
// without a context are the plain radiance-mode models.
#pragma once

#include <memory>
#include <optional>
#include <variant>

#include "bsdfs/bsdf_context.hpp"
#include "bsdfs/conductor.hpp"
#include "bsdfs/ior.hpp"
#include "bsdfs/dielectric.hpp"
#include "bsdfs/phong.hpp"
#include "bsdfs/plastic.hpp"
#include "bsdfs/roughconductor.hpp"
#include "bsdfs/roughdielectric.hpp"
#include "bsdfs/roughplastic.hpp"
#include "bsdfs/thindielectric.hpp"

namespace pathlab {

struct Material;

// blendbsdf: (1 - weight) * first + weight * second (Mitsuba's blendbsdf with a constant
// weight; a texture weight needs textures). Sampling picks a BSDF with probability 1 - weight
// or weight; eval and pdf mix both (their non-delta lobes), a delta sample keeps its own
// coefficient times the choice's probability (bsdf_sample.hpp).
struct BlendMaterial {
    std::shared_ptr<const Material> first, second;
    float weight = 0.5f;  // of `second`

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const;
    float pdf(const Vec3f& wi, const Vec3f& wo) const;
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const;
};

// mask: opacity * the nested BSDF, and with probability 1 - opacity the path goes straight
// through (a Dirac delta along -wi of coefficient 1 - opacity, on either side). A constant
// opacity (a texture needs textures).
struct MaskMaterial {
    std::shared_ptr<const Material> inner;
    float opacity = 0.5f;

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const;
    float pdf(const Vec3f& wi, const Vec3f& wo) const;
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const;
};

// One BSDF per header (parameters and defaults documented at the top of each).
using MaterialModel = std::variant<PhongMaterial, ConductorMaterial, DielectricMaterial, RoughConductorMaterial,
                                   RoughDielectricMaterial, PlasticMaterial, RoughPlasticMaterial, ThinDielectricMaterial,
                                   BlendMaterial, MaskMaterial>;

// std::visit, as a switch that the compiler always inlines: the hot loop calls sample() at
// several places, and an out-of-line dispatch there cost about 3% of pt-mis's time.
template <typename F>
[[gnu::always_inline]] inline decltype(auto) visit_model(const MaterialModel& model, F&& f) {
    static_assert(std::variant_size_v<MaterialModel> == 10, "add the new model's case below");
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
        default: return f(*std::get_if<9>(&model));
    }
}

struct Material {
    MaterialModel model;
    // Two-sided materials shade the back of a surface like its front (the frame is flipped
    // to face the incoming direction); one-sided ones are black from behind. A dielectric
    // is neither: both of its sides are meaningful, and its frame is never flipped.
    bool two_sided = true;
    // twosided with two BSDFs: the index (in the scene's materials) of the one for the back,
    // used with the frame flipped as for the front; -1: the same material on both sides.
    int32_t back = -1;

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
    // ---- with a shading context (transport mode, reverse pdf) ----------------------------
    // Radiance mode without a reverse pdf is the plain model and stays inline (the path
    // tracers' hot loop); the rest takes the out-of-line adjusted path.
    Rgb eval(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const {
        if (ctx.mode == TransportMode::Radiance) [[likely]]
            return eval(wi, wo);
        return eval(wi, wo) * importance_factor(ctx, wi, wo);
    }
    float pdf(const BsdfContext&, const Vec3f& wi, const Vec3f& wo) const { return pdf(wi, wo); }
    Rgb eval_and_pdf(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        if (ctx.mode == TransportMode::Radiance) [[likely]]
            return eval_and_pdf(wi, wo, pdf);
        return eval_and_pdf(wi, wo, pdf) * importance_factor(ctx, wi, wo);
    }
    [[gnu::always_inline]] std::optional<BsdfSample> sample(const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u) const {
        if (ctx.mode == TransportMode::Radiance && !ctx.reverse_pdf) [[likely]]
            return sample(wi, u);
        return sample_adjusted(ctx, wi, u);
    }
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
        return std::holds_alternative<DielectricMaterial>(model) || std::holds_alternative<RoughDielectricMaterial>(model);
    }

    // The context's adjustments (material.cpp: out of line, so that the hot path's visit of the
    // model stays the only one in the integrators' code and is inlined there).
    std::optional<BsdfSample> sample_adjusted(const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u) const;

    // What importance transport multiplies the radiance-mode BSDF by (bsdf_context.hpp): the
    // refraction factor (eta_wo / eta_wi)^2 and the shading-normal correction; 0 for directions
    // on different sides of the geometric and the shading surface.
    float importance_factor(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const;

private:
    static uint32_t lobes_of(const PhongMaterial& m) {
        return kLobeReflection | (pathlab::is_black(m.diffuse) ? 0u : kLobeDiffuse) | (pathlab::is_black(m.specular) ? 0u : kLobeGlossy);
    }
    static uint32_t lobes_of(const ConductorMaterial&) { return kLobeSpecular | kLobeReflection; }
    static uint32_t lobes_of(const DielectricMaterial&) { return kLobeSpecular | kLobeReflection | kLobeTransmission; }
    static uint32_t lobes_of(const RoughConductorMaterial&) { return kLobeGlossy | kLobeReflection; }
    static uint32_t lobes_of(const RoughDielectricMaterial&) { return kLobeGlossy | kLobeReflection | kLobeTransmission; }
    static uint32_t lobes_of(const PlasticMaterial&) { return kLobeDiffuse | kLobeSpecular | kLobeReflection; }
    static uint32_t lobes_of(const RoughPlasticMaterial&) { return kLobeDiffuse | kLobeGlossy | kLobeReflection; }
    static uint32_t lobes_of(const ThinDielectricMaterial&) { return kLobeSpecular | kLobeReflection | kLobeTransmission; }
    static uint32_t lobes_of(const BlendMaterial& m) { return m.first->lobes() | m.second->lobes(); }
    static uint32_t lobes_of(const MaskMaterial& m) { return m.inner->lobes() | kLobeSpecular | kLobeTransmission; }
};

// The diffuse reflectance (Mitsuba's aov "albedo"): Lambertian and Phong's rho_d, a coated
// base's rho, mixtures of them; 0 for purely glossy or specular materials.
inline Rgb diffuse_albedo(const Material& m) {
    if (const auto* p = std::get_if<PhongMaterial>(&m.model)) return p->diffuse;
    if (const auto* p = std::get_if<PlasticMaterial>(&m.model)) return p->coat.diffuse_reflectance;
    if (const auto* p = std::get_if<RoughPlasticMaterial>(&m.model)) return p->coat.diffuse_reflectance;
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
    return Material{ConductorMaterial{ior.eta, ior.k, reflectance}};
}
inline Material make_rough_conductor(const MicrofacetDistribution& d, const ComplexIor& ior = {Rgb(0.0f), Rgb(1.0f)},
                                     const Rgb& reflectance = Rgb(1.0f)) {
    return Material{RoughConductorMaterial{d, ior.eta, ior.k, reflectance}};
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
