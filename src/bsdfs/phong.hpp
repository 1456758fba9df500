// The course's material: Lambertian diffuse plus the normalised modified Phong lobe,
//   f(wi, wo) = rho_d / pi + rho_s (n + 2) / (2 pi) max(0, cos alpha)^n,
// where alpha is the angle between wo and the mirror reflection of wi about the normal.
// With rho_s = 0 it is a plain Lambertian BRDF. Directions are in the local shading frame
// (normal = +z), both pointing away from the surface; the BRDF is zero unless both are above it.
//
// Sampling (assignment 2C): choose the diffuse lobe with probability
// mean(rho_d) / (mean(rho_d) + mean(rho_s)), else the Phong lobe; sample the chosen lobe
// (cosine hemisphere, or cos^n around the mirror direction); the returned pdf is the mixture
// of both lobes' pdfs for the final direction. Phong-lobe directions below the surface are
// rejected (no sample), so pdf() integrates to 1 minus that lost mass over the hemisphere.
#pragma once

#include <optional>

#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "core/vec.hpp"
#include "bsdfs/bsdf_sample.hpp"
#include "core/properties.hpp"

namespace pathlab {

struct PhongMaterial {
    Rgb diffuse{0.0f};   // rho_d
    Rgb specular{0.0f};  // rho_s
    float exponent = 1;  // n

    // Probability of sampling the diffuse lobe.
    float diffuse_probability() const {
        const float d = mean(diffuse), s = mean(specular);
        return d + s > 0 ? d / (d + s) : 0.0f;
    }

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const {
        float unused;
        return eval_and_pdf(wi, wo, unused);
    }

    float pdf(const Vec3f& wi, const Vec3f& wo) const {
        float p;
        eval_and_pdf(wi, wo, p);
        return p;
    }

    // Both at once, sharing the one pow() they need (the hot path of light sampling with MIS).
    Rgb eval_and_pdf(const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        pdf = 0;
        if (wi.z <= 0 || wo.z <= 0) return Rgb(0.0f);
        const float pd = diffuse_probability();
        Rgb f = diffuse * kInvPi;
        pdf = pd * cosine_hemisphere_pdf(wo);
        if (pd < 1) {
            const float cos_alpha = dot(mirror(wi), wo);
            if (cos_alpha > 0) {
                const float lobe = std::pow(cos_alpha, exponent) * (1 / (2 * kPi));  // cos^n / (2 pi)
                f += specular * ((exponent + 2) * lobe);
                pdf += (1 - pd) * (exponent + 1) * lobe;  // the normalised cos^n lobe, as power_cosine_pdf
            }
        }
        return f;
    }

    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        if (wi.z <= 0 || (is_black(diffuse) && is_black(specular))) return std::nullopt;
        const float pd = diffuse_probability();
        Vec3f wo;
        const uint32_t lobe = kLobeReflection | (u.x < pd ? kLobeDiffuse : kLobeGlossy);
        if (u.x < pd) {
            u.x /= pd;
            wo = square_to_cosine_hemisphere(u);
        } else {
            u.x = std::min((u.x - pd) / (1 - pd), 0x1.fffffep-1f);
            wo = Frame(mirror(wi)).to_world(square_to_power_cosine(u, exponent));
        }
        if (wo.z <= 0) return std::nullopt;
        float p;
        const Rgb f = eval_and_pdf(wi, wo, p);
        if (!(p > 0)) return std::nullopt;
        return BsdfSample{wo, f, p, false, lobe};
    }

    static Vec3f mirror(const Vec3f& w) { return {-w.x, -w.y, w.z}; }

    // The parameters a texture may give (ParamInfo::texture_slot), and setting one to its
    // value at a hit.
    static constexpr int kSlotDiffuse = 0, kSlotSpecular = 1, kSlotExponent = 2;
    void set_texel(int slot, const Rgb& v) {
        if (slot == kSlotDiffuse) diffuse = v;
        else if (slot == kSlotSpecular) specular = v;
        else exponent = v.x;
    }
};

// The scene-file plugins: diffuse (Lambert, Mitsuba 3) and phong (Mitsuba 0.6, the course's
// normalised Phong).
inline const PluginInfo& diffuse_plugin() {
    static const PluginInfo info{"bsdf", "diffuse", "Lambertian reflection rho / pi",
                                 {{"reflectance", ParamType::Rgb, "0.5", "albedo rho", "", PhongMaterial::kSlotDiffuse}}};
    return info;
}
inline PhongMaterial read_diffuse(Properties& p) { return PhongMaterial{p.get_rgb("reflectance"), Rgb(0.0f), 1}; }

inline const PluginInfo& phong_plugin() {
    static const PluginInfo info{
        "bsdf", "phong", "the course's normalised Phong: rho_d / pi + rho_s (n + 2) / (2 pi) cos^n of the angle to the mirror direction",
        {{"diffuse_reflectance", ParamType::Rgb, "0.5", "rho_d", "diffuseReflectance", PhongMaterial::kSlotDiffuse},
         {"specular_reflectance", ParamType::Rgb, "0.2", "rho_s", "specularReflectance", PhongMaterial::kSlotSpecular},
         {"exponent", ParamType::Float, "30", "n", "", PhongMaterial::kSlotExponent}}};
    return info;
}
inline PhongMaterial read_phong(Properties& p) {
    const Rgb kd = p.get_rgb("diffuse_reflectance"), ks = p.get_rgb("specular_reflectance");
    const float exponent = p.get_float("exponent");
    if (!(exponent >= 0)) p.fail("the Phong exponent must not be negative");
    return PhongMaterial{kd, ks, exponent};
}

}  // namespace pathlab
