// principledthin: the thin-sheet variant of the Disney BSDF (Burley 2015, "Extending the Disney
// BRDF to a BSDF with integrated subsurface scattering", section 5.3) as Mitsuba 3 defines it
// (src/bsdfs/principledthin.cpp and principledhelpers.h there): a surface of no thickness
// (leaves, paper, curtains, a window pane as one quad) that reflects and transmits without
// bending light, the same from both sides. With base colour c, s = spec_trans, d = diff_trans /
// 2 and, from either side, wi and wo mirrored so that wi is on the front:
//   specular reflection     s F(wi.h) D(h) G(wi, wo) / (4 cos_i cos_o)      (GGX of the roughness)
//     F = (1 - spec_tint) F_d + spec_tint Schlick(R0(eta) c / lum(c))
//   specular transmission   s c (1 - F_d(wi.h)) D'(h) G'(wi, wo) / (4 cos_i |cos_o|), h the half
//                           vector of wi and wo mirrored to the front (the sheet reflects about a
//                           microfacet and lets the light through: no refraction), D' and G'
//                           GGX's with the roughness scaled by 0.65 eta - 0.35 (Burley's Figure 15)
//   diffuse reflection      (1 - s)(1 - d) c / pi (Burley's diffuse with retro-reflection,
//                           flattened by `flatness`), plus the sheen (1 - s)(1 - d) sheen
//                           Schlick_weight(wo.h) lerp(1, c / lum(c), sheen_tint)
//   diffuse transmission    (1 - s) d c / pi
// F_d is the dielectric Fresnel term of eta at the microfacet. The specular lobes need the
// microfacet on the side Mitsuba's mac_mic_compatibility asks (wi.h > 0, and wo.h > 0 in
// reflection, < 0 in transmission). Every term is A + B c with scalars A, B (lum(c) from the RGB
// base colour): PrincipledMaterial::Terms, evaluated by spectral mode at the path's wavelengths.
//
// XML (Mitsuba 3's names):
//   base_color                           rgb or texture    c                                default 0.5
//   roughness, anisotropic, spec_trans,  float or texture  each in [0, 1]                   default 0.5 (roughness), else 0
//   spec_tint, sheen_tint, flatness
//   sheen                                float or texture  not negative                     default 0
//   diff_trans                           float or texture  0 (diffuse reflection only) to 2 (diffuse transmission only)   default 0
//   eta                                  float             the sheet's relative index (its Fresnel term)   default 1.5
//   specular_reflectance_sampling_rate, specular_transmittance_sampling_rate,
//   diffuse_reflectance_sampling_rate, diffuse_transmittance_sampling_rate
//                                        float             positive factors of the lobes' probabilities     default 1
//
// Sampling as Mitsuba's: a lobe with probability proportional to s rate / 2 (each specular
// lobe), (1 - s)(1 - d) rate (diffuse reflection), (1 - s) d rate (diffuse transmission); the
// specular lobes sample their GGX's visible normals, the diffuse ones the cosine-weighted
// hemisphere; pdf() is that mixture's density (a sampled microfacet on the wrong side gives no
// sample, as in Mitsuba).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/properties.hpp"
#include "core/sampling.hpp"
#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/microfacet.hpp"
#include "bsdfs/principled.hpp"

namespace pathlab {

struct PrincipledThinMaterial {
    Rgb base_color{0.5f};
    float roughness = 0.5f, anisotropic = 0, spec_trans = 0, spec_tint = 0, sheen = 0, sheen_tint = 0, flatness = 0;
    float diff_trans = 0;  // as given: 0 to 2
    float eta = 1.5f;
    float rate_spec_reflect = 1, rate_spec_trans = 1, rate_diff_reflect = 1, rate_diff_trans = 1;

    // The parameters textures may give (ParamInfo::texture_slot).
    enum Slot : int {
        kSlotBaseColor, kSlotRoughness, kSlotAnisotropic, kSlotSpecTrans, kSlotSpecTint, kSlotSheen, kSlotSheenTint, kSlotFlatness,
        kSlotDiffTrans,
    };
    void set_texel(int slot, const Rgb& v) {
        if (slot == kSlotBaseColor) {
            base_color = v;
            return;
        }
        float* const fields[] = {nullptr, &roughness, &anisotropic, &spec_trans, &spec_tint, &sheen, &sheen_tint, &flatness, &diff_trans};
        if (slot > 0 && slot <= kSlotDiffTrans) *fields[slot] = v.x;
    }

    using Terms = PrincipledMaterial::Terms;

    MicrofacetDistribution reflection_distribution() const { return disney::specular_distribution(roughness, anisotropic); }
    MicrofacetDistribution transmission_distribution() const {
        return disney::specular_distribution((0.65f * eta - 0.35f) * roughness, anisotropic);
    }
    // The lobes' selection probabilities (they do not depend on the directions).
    struct LobeChoice {
        float spec_reflect = 0, spec_trans = 0, diff_reflect = 0, diff_trans = 0;
    };
    LobeChoice lobe_choice() const {
        const float d = diff_trans / 2;
        LobeChoice p{spec_trans * rate_spec_reflect / 2, spec_trans * rate_spec_trans / 2, rate_diff_reflect * (1 - spec_trans) * (1 - d),
                     rate_diff_trans * (1 - spec_trans) * d};
        const float total = p.spec_reflect + p.spec_trans + p.diff_reflect + p.diff_trans;
        if (!(total > 0)) return LobeChoice{};
        p.spec_reflect /= total, p.spec_trans /= total, p.diff_reflect /= total, p.diff_trans /= total;
        return p;
    }

    Terms terms(const Vec3f& wi_in, const Vec3f& wo_in, float& pdf) const;

    Rgb eval_and_pdf(const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        const Terms t = terms(wi, wo, pdf);
        return Rgb(t.a) + base_color * t.b;
    }
    Rgb eval(const Vec3f& wi, const Vec3f& wo) const {
        float unused;
        return eval_and_pdf(wi, wo, unused);
    }
    float pdf(const Vec3f& wi, const Vec3f& wo) const {
        float p;
        terms(wi, wo, p);
        return p;
    }
    std::optional<BsdfSample> sample(const Vec3f& wi_in, Vec2f u) const;
};

inline PrincipledThinMaterial::Terms PrincipledThinMaterial::terms(const Vec3f& wi_in, const Vec3f& wo_in, float& pdf) const {
    pdf = 0;
    Terms t;
    if (wi_in.z == 0 || wo_in.z == 0) return t;
    // The sheet is the same from both sides: mirror both directions so that wi is on the front.
    const bool front = wi_in.z > 0;
    const Vec3f wi = front ? wi_in : Vec3f(wi_in.x, wi_in.y, -wi_in.z);
    const Vec3f wo = front ? wo_in : Vec3f(wo_in.x, wo_in.y, -wo_in.z);
    const bool reflect = wo.z > 0;
    const float cos_o = std::abs(wo.z), d = diff_trans / 2, lum = luminance(base_color);
    const LobeChoice p = lobe_choice();
    // A multiple k of c / lum(c) (the tints): to b, or to a where lum is 0 (the tint is then 1).
    const auto add_tint = [&](float k) { (lum > 0 ? t.b : t.a) += lum > 0 ? k / lum : k; };
    // The half vector of wi and wo mirrored to the front (the specular transmission reflects
    // about a microfacet, then passes through).
    const Vec3f h = normalize(wi + Vec3f(wo.x, wo.y, cos_o));
    const float ci = dot(wi, h), co = dot(wo, h);
    if (spec_trans > 0 && ci > 0 && (reflect ? co > 0 : co < 0)) {
        const float F_d = fresnel_dielectric(ci, eta), jacobian = 1 / (4 * std::abs(dot(Vec3f(wo.x, wo.y, cos_o), h)));
        if (reflect) {
            const MicrofacetDistribution dist = reflection_distribution();
            const float k = spec_trans * dist.D(h) * dist.G2(wi, wo) / (4 * wi.z * cos_o);
            const float w = disney::schlick_weight_front(ci, eta);
            t.a += k * ((1 - spec_tint) * F_d + spec_tint * w);
            add_tint(k * spec_tint * (1 - w) * disney::schlick_r0(eta));
            pdf += p.spec_reflect * dist.pdf(wi, h) * jacobian;
        } else {
            const MicrofacetDistribution dist = transmission_distribution();
            t.b += spec_trans * (1 - F_d) * dist.D(h) * dist.G2(wi, wo) / (4 * wi.z * cos_o);
            pdf += p.spec_trans * dist.pdf(wi, h) * jacobian;
        }
    }
    if (reflect) {
        pdf += p.diff_reflect * cos_o * kInvPi;
        if (spec_trans < 1 && d < 1) {
            const float cos_d = dot(h, wo), k = (1 - spec_trans) * (1 - d);
            t.b += k * kInvPi * disney::diffuse_shape(wi.z, cos_o, cos_d, roughness, flatness);
            if (sheen > 0) {
                const float s = k * sheen * disney::schlick_weight(std::abs(cos_d));
                t.a += s * (1 - sheen_tint);
                add_tint(s * sheen_tint);
            }
        }
    } else {
        pdf += p.diff_trans * cos_o * kInvPi;
        if (spec_trans < 1 && d > 0) t.b += (1 - spec_trans) * d * kInvPi;
    }
    return t;
}

inline std::optional<BsdfSample> PrincipledThinMaterial::sample(const Vec3f& wi_in, Vec2f u) const {
    if (wi_in.z == 0) return std::nullopt;
    const bool front = wi_in.z > 0;
    const Vec3f wi(wi_in.x, wi_in.y, std::abs(wi_in.z));
    const LobeChoice p = lobe_choice();
    // The lobe, and u.x rescaled to [0, 1) within its share.
    const float shares[4] = {p.spec_reflect, p.spec_trans, p.diff_reflect, p.diff_trans};
    int lobe = 0;
    float start = 0;
    while (lobe < 3 && !(u.x < start + shares[lobe])) start += shares[lobe++];
    if (!(shares[lobe] > 0)) return std::nullopt;
    u.x = std::min((u.x - start) / shares[lobe], 0x1.fffffep-1f);
    Vec3f wo;
    uint32_t flags = 0;
    if (lobe < 2) {
        const Vec3f m = (lobe == 0 ? reflection_distribution() : transmission_distribution()).sample(wi, u);
        if (!(dot(wi, m) > 0)) return std::nullopt;
        wo = pathlab::reflect(wi, m);
        if (!(wo.z > 0)) return std::nullopt;
        flags = kLobeGlossy | kLobeReflection;
        if (lobe == 1) {
            wo.z = -wo.z;  // through the sheet, unbent
            if (!(dot(wo, m) < 0)) return std::nullopt;
            flags = kLobeGlossy | kLobeTransmission;
        }
    } else {
        wo = square_to_cosine_hemisphere(u);
        flags = kLobeDiffuse | kLobeReflection;
        if (lobe == 3) wo.z = -wo.z, flags = kLobeDiffuse | kLobeTransmission;
    }
    if (!front) wo.z = -wo.z;
    float pdf;
    const Rgb f = eval_and_pdf(wi_in, wo, pdf);
    if (!(pdf > 0)) return std::nullopt;
    return BsdfSample{wo, f, pdf, false, flags};
}

inline const PluginInfo& principledthin_plugin() {
    using S = PrincipledThinMaterial::Slot;
    static const PluginInfo info{
        "bsdf",
        "principledthin",
        "the Disney BSDF of a thin sheet as Mitsuba 3 defines it: specular and diffuse reflection and transmission without refraction",
        {{"base_color", ParamType::Rgb, "0.5", "base colour c", "", S::kSlotBaseColor},
         {"roughness", ParamType::Float, "0.5", "0 (smooth) to 1", "", S::kSlotRoughness},
         {"anisotropic", ParamType::Float, "0", "0 to 1: stretches the highlight along dp/du", "", S::kSlotAnisotropic},
         {"spec_trans", ParamType::Float, "0", "0 to 1: the share of the specular lobes (reflection and transmission)", "", S::kSlotSpecTrans},
         {"spec_tint", ParamType::Float, "0", "0 to 1: tints the specular reflection towards c", "", S::kSlotSpecTint},
         {"sheen", ParamType::Float, "0", "retro-reflective grazing sheen (cloth), not negative", "", S::kSlotSheen},
         {"sheen_tint", ParamType::Float, "0", "0 to 1: tints the sheen towards c", "", S::kSlotSheenTint},
         {"flatness", ParamType::Float, "0", "0 to 1: flattens the diffuse lobe (fake subsurface)", "", S::kSlotFlatness},
         {"diff_trans", ParamType::Float, "0", "0 (diffuse reflection only) to 2 (diffuse transmission only)", "", S::kSlotDiffTrans},
         {"eta", ParamType::Float, "1.5", "the sheet's relative index of refraction (its Fresnel term; light is not bent)"},
         {"specular_reflectance_sampling_rate", ParamType::Float, "1", "factor of the specular reflection's sampling probability"},
         {"specular_transmittance_sampling_rate", ParamType::Float, "1", "factor of the specular transmission's sampling probability"},
         {"diffuse_reflectance_sampling_rate", ParamType::Float, "1", "factor of the diffuse reflection's sampling probability"},
         {"diffuse_transmittance_sampling_rate", ParamType::Float, "1", "factor of the diffuse transmission's sampling probability"}}};
    return info;
}

inline PrincipledThinMaterial read_principledthin(Properties& p) {
    PrincipledThinMaterial m;
    m.base_color = p.get_rgb("base_color");
    const auto in = [&](const char* name, float hi) {
        const float v = p.get_float(name);
        if (!(v >= 0 && v <= hi)) p.fail(name, fmt::format("{} must be between 0 and {}, got {}", name, hi, v));
        return v;
    };
    m.roughness = in("roughness", 1);
    m.anisotropic = in("anisotropic", 1);
    m.spec_trans = in("spec_trans", 1);
    m.spec_tint = in("spec_tint", 1);
    m.sheen_tint = in("sheen_tint", 1);
    m.flatness = in("flatness", 1);
    m.diff_trans = in("diff_trans", 2);
    m.sheen = p.get_float("sheen");
    if (!(m.sheen >= 0 && m.sheen < 1e6f)) p.fail("sheen", fmt::format("sheen must not be negative, got {}", m.sheen));
    m.eta = p.get_float("eta");
    if (!(m.eta > 0 && m.eta < 100)) p.fail("eta", fmt::format("eta must be positive, got {}", m.eta));
    const auto rate = [&](const char* name) {
        const float v = p.get_float(name);
        if (!(v > 0 && v < 1e6f)) p.fail(name, fmt::format("{} must be positive, got {} (a lobe never sampled would be missed)", name, v));
        return v;
    };
    m.rate_spec_reflect = rate("specular_reflectance_sampling_rate");
    m.rate_spec_trans = rate("specular_transmittance_sampling_rate");
    m.rate_diff_reflect = rate("diffuse_reflectance_sampling_rate");
    m.rate_diff_trans = rate("diffuse_transmittance_sampling_rate");
    return m;
}

}  // namespace pathlab
