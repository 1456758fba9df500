// plastic: a diffuse base under a smooth dielectric coating (Mitsuba's plastic). Light is
// either reflected specularly by the coating (a Dirac delta, Fresnel F(cos_i) times the
// specular reflectance) or refracted into it, scattered diffusely by the base (with its
// internal reflections at the coating summed up) and refracted out:
//   f_diffuse(wi, wo) = rho' (1 - F(cos_i)) (1 - F(cos_o)) / (pi eta^2),
//   rho' = rho / (1 - Fdr)      (linear: the default)
//   rho' = rho / (1 - rho Fdr)  (nonlinear = true: repeated bounces darken and saturate the colour)
// with eta = int_ior / ext_ior and Fdr the coating's internal hemispherical reflectance
// (fresnel.hpp). With rho = 1 and a specular reflectance of 1 the albedo is exactly 1 at
// every angle: 1 - Fdr(1/eta) = (1 - Fdr(eta)) / eta^2.
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   diffuse_reflectance   rgb              rho, the base's albedo                   default 0.5
//   specular_reflectance  rgb              scales the coating's reflection          default 1
//   int_ior               float or string  coating index, or a name                 default polypropylene (1.49)
//   ext_ior               float or string  exterior index                           default air (1.000277)
//   nonlinear             boolean          see above                                default false
// One-sided unless wrapped in twosided.
//
// A mixture of a delta lobe and a non-delta one: sample() picks the coating's reflection
// with probability P_s = F w / (F w + (1 - F)(1 - w)), w = mean(specular) / (mean(specular) +
// mean(diffuse)), returning it as a delta sample (pdfW = P_s); otherwise a cosine-weighted
// direction with f = eval() and pdfW = pdf() = (1 - P_s) cos_o / pi. eval() and pdf() hold
// only the diffuse part, so light sampling and MIS handle it, and is_delta() is false.
#pragma once

#include <optional>

#include "core/sampling.hpp"
#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/ior.hpp"

namespace pathlab {

// What plastic and roughplastic share: the diffuse base seen through the coating.
struct CoatedDiffuse {
    Rgb diffuse_reflectance{0.5f};
    Rgb specular_reflectance{1.0f};
    float eta = 1.49f / 1.000277f;  // int_ior / ext_ior
    bool nonlinear = false;
    float fdr = 0;                  // the coating's internal diffuse reflectance Fdr
    Rgb base{0.0f};                 // rho' / (pi eta^2), precomputed
    float specular_weight = 0.5f;   // w

    CoatedDiffuse() = default;
    CoatedDiffuse(const Rgb& diffuse, const Rgb& specular, float int_ior, float ext_ior, bool nonlinear_)
        : diffuse_reflectance(diffuse), specular_reflectance(specular), eta(int_ior / ext_ior), nonlinear(nonlinear_),
          fdr(fresnel_diffuse_reflectance(1 / eta)) {
        update();
    }
    // Recomputes what depends on the reflectances and Fdr (after a texture set them).
    void update() {
        const Rgb denom = nonlinear ? Rgb(1.0f) - diffuse_reflectance * fdr : Rgb(1.0f - fdr);
        base = diffuse_reflectance / denom * (kInvPi / (eta * eta));
        const float s = mean(specular_reflectance), d = mean(diffuse_reflectance);
        specular_weight = s + d > 0 ? s / (s + d) : 0.0f;
    }

    // The parameters a texture may give, and setting one to its value at a hit (update() after).
    static constexpr int kSlotDiffuse = 0, kSlotSpecular = 1;
    void set_texel(int slot, const Rgb& v) { (slot == kSlotDiffuse ? diffuse_reflectance : specular_reflectance) = v; }

    float fresnel(float cos) const { return fresnel_dielectric(cos, eta); }
    Rgb diffuse(float F_i, float cos_o) const { return base * ((1 - F_i) * (1 - fresnel(cos_o))); }
    float specular_probability(float F_i) const {
        const float s = F_i * specular_weight, d = (1 - F_i) * (1 - specular_weight);
        return s + d > 0 ? s / (s + d) : 0.0f;
    }
};

struct PlasticMaterial {
    CoatedDiffuse coat;

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const {
        if (wi.z <= 0 || wo.z <= 0) return Rgb(0.0f);
        return coat.diffuse(coat.fresnel(wi.z), wo.z);
    }
    float pdf(const Vec3f& wi, const Vec3f& wo) const {
        if (wi.z <= 0 || wo.z <= 0) return 0.0f;
        return (1 - coat.specular_probability(coat.fresnel(wi.z))) * cosine_hemisphere_pdf(wo);
    }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        if (wi.z <= 0) return std::nullopt;
        const float F = coat.fresnel(wi.z), ps = coat.specular_probability(F);
        if (u.x < ps) {
            const Vec3f wo(-wi.x, -wi.y, wi.z);
            return BsdfSample{wo, coat.specular_reflectance * (F / wo.z), ps, true, kLobeSpecular | kLobeReflection};
        }
        u.x = std::min((u.x - ps) / (1 - ps), 0x1.fffffep-1f);
        const Vec3f wo = square_to_cosine_hemisphere(u);
        if (wo.z <= 0) return std::nullopt;
        const float p = (1 - ps) * cosine_hemisphere_pdf(wo);
        if (!(p > 0)) return std::nullopt;
        return BsdfSample{wo, coat.diffuse(F, wo.z), p, false, kLobeDiffuse | kLobeReflection};
    }

    void set_texel(int slot, const Rgb& v) { coat.set_texel(slot, v); }
    void texels_changed() { coat.update(); }
};

inline std::vector<ParamInfo> coated_diffuse_params() {
    return {{"diffuse_reflectance", ParamType::Rgb, "0.5", "rho, the albedo of the diffuse base", "diffuseReflectance",
             CoatedDiffuse::kSlotDiffuse},
            {"specular_reflectance", ParamType::Rgb, "1", "scales the coating's reflection", "specularReflectance",
             CoatedDiffuse::kSlotSpecular},
            {"int_ior", ParamType::FloatOrString, "polypropylene", "index of the coating, a number or a name", "intIOR"},
            {"ext_ior", ParamType::FloatOrString, "air", "index of the outside", "extIOR"},
            {"nonlinear", ParamType::Boolean, "false",
             "the base's internal reflections also tint and darken its colour (rho / (1 - rho Fdr) instead of rho / (1 - Fdr))"}};
}
inline CoatedDiffuse read_coated_diffuse(Properties& p) {
    const Rgb kd = p.get_rgb("diffuse_reflectance"), ks = p.get_rgb("specular_reflectance");
    const float int_ior = read_ior(p, "int_ior"), ext_ior = read_ior(p, "ext_ior");
    if (int_ior == ext_ior) p.fail("int_ior and ext_ior are equal: the coating would be invisible");
    return CoatedDiffuse(kd, ks, int_ior, ext_ior, p.get_bool("nonlinear"));
}

inline const PluginInfo& plastic_plugin() {
    static const PluginInfo info{"bsdf", "plastic", "a diffuse base under a smooth dielectric coating", coated_diffuse_params()};
    return info;
}
inline PlasticMaterial read_plastic(Properties& p) { return PlasticMaterial{read_coated_diffuse(p)}; }

}  // namespace pathlab
