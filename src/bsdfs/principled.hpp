// principled: the Disney BSDF (Burley 2012, "Physically-based shading at Disney"; 2015,
// "Extending the Disney BRDF to a BSDF with integrated subsurface scattering") as Mitsuba 3
// defines it (src/bsdfs/principled.cpp and principledhelpers.h there), so that its scenes
// render as their authors saw them. With base colour c, weights brdf = (1 - metallic)
// (1 - spec_trans) and bsdf = (1 - metallic) spec_trans, and wi on the front side:
//   main specular   F_p(wi.h) D(h) G(wi, wo) / (4 cos_i cos_o)          (GGX, anisotropic)
//     F_p = (1 - metallic)(1 - spec_tint) F_d + metallic Schlick(c) + (1 - metallic) spec_tint Schlick(R0(eta) c / lum(c))
//   transmission    sqrt(c) bsdf (1 - F_d) D G |wi.h| |wo.h| / (cos_i |cos_o| (wi.h + eta wo.h)^2)   (radiance)
//   clearcoat       clearcoat / 4 Schlick(0.04) D_GTR1(h) G_cc(wi, wo)   (Mitsuba's clearcoat lobe: not
//                   divided by 4 cos_i cos_o as Burley's is)
//   diffuse         brdf c / pi ((1 - Fi/2)(1 - Fo/2) + retro-reflection), lerped towards Hanrahan-
//                   Krueger's flattened shape by `flatness`
//   sheen           sheen (1 - metallic) Schlick_weight(wo.h) lerp(1, c / lum(c), sheen_tint)   (with brdf > 0)
// F_d is the dielectric Fresnel term of the relative index eta, Schlick(R0) = R0 + (1 - R0)
// (1 - cos)^5, D and G are GGX's with alpha_u = max(0.001, r^2 / a), alpha_v = max(0.001, r^2 a),
// a = sqrt(1 - 0.9 anisotropic), r the roughness; the clearcoat's GTR1 has alpha = lerp(0.1,
// 0.001, clearcoat_gloss), its masking is GGX's with alpha 0.25. From behind (wi.z < 0) only the
// main specular reflection (bsdf F_d) and the transmission are seen, with the relative index 1 / eta.
// Every term is A + B c + C sqrt(c) with scalars A, B, C (lum(c) taken from the RGB base
// colour), which is how spectral mode evaluates it at a path's wavelengths (Terms below).
//
// XML (Mitsuba 3's names):
//   base_color                          rgb or texture    c                                  default 0.5
//   roughness, anisotropic, metallic,   float or texture  each in [0, 1]                     default 0.5 (roughness), else 0
//   spec_trans, spec_tint, sheen_tint,
//   clearcoat, clearcoat_gloss, flatness
//   sheen                               float or texture  not negative                       default 0
//   specular                            float             R0 = 0.08 specular: eta = 2 / (1 - sqrt(0.08 specular)) - 1   default 0.5 (eta 1.5)
//   eta                                 float             the relative index (instead of specular)
//   main_specular_sampling_rate, clearcoat_sampling_rate, diffuse_reflectance_sampling_rate
//                                       float             positive factors of the lobes' sampling probabilities   default 1
// With spec_trans the material transmits (both of its sides matter: it cannot be wrapped in
// twosided, as in Mitsuba); without it, it is one-sided (black from behind) unless wrapped.
//
// Sampling (pathlab's, not Mitsuba's): a lobe is chosen with probabilities proportional to
// Mitsuba's lobe weights, with the Fresnel term of the macro surface F_d(cos_i) where Mitsuba
// takes the one of the microfacet it sampled for its other lobe: Mitsuba's choice of the
// diffuse or clearcoat lobe then depends on a normal it does not use, and its pdf() is not the
// density its sample() draws from when the material transmits. Here the choice depends on wi
// alone and pdf() is the exact mixture: front side p_spec = 1 - bsdf (1 - F), p_trans = bsdf
// (1 - F), p_clearcoat = clearcoat / 4, p_diffuse = brdf (times the sampling rates, then
// normalised); back side p_spec = F, p_trans = 1 - F. The specular lobes sample GGX's visible
// normals, the clearcoat GTR1's normals, the diffuse lobe the cosine-weighted hemisphere.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/properties.hpp"
#include "core/sampling.hpp"
#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/microfacet.hpp"
#include "bsdfs/roughdielectric.hpp"

namespace pathlab {

// Pieces principled and principledthin share (Mitsuba's principledhelpers.h).
namespace disney {

// Schlick's weight (1 - cos)^5, clamped as Mitsuba's schlick_weight.
inline float schlick_weight(float cos) {
    const float m = std::clamp(1 - cos, 0.0f, 1.0f);
    return m * m * m * m * m;
}
// The weight w of Schlick(R0) = R0 (1 - w) + w at the microfacet cosine cos (> 0) on the front
// side of a surface of relative index eta: from the cosine of the refracted direction where
// eta < 1 (calc_schlick).
inline float schlick_weight_front(float cos, float eta) {
    if (eta > 1) return schlick_weight(cos);
    const float cos_t2 = 1 - (1 - cos * cos) * (eta * eta);
    return schlick_weight(std::sqrt(std::max(0.0f, cos_t2)));
}
// Schlick's R0 of the relative index eta.
inline float schlick_r0(float eta) { return (eta - 1) * (eta - 1) / ((eta + 1) * (eta + 1)); }
// GGX of the roughness r and anisotropy a: alpha_u = max(0.001, r^2 / s), alpha_v = max(0.001,
// r^2 s), s = sqrt(1 - 0.9 a) (calc_dist_params).
inline MicrofacetDistribution specular_distribution(float roughness, float anisotropic) {
    const float r2 = roughness * roughness, aspect = std::sqrt(1 - 0.9f * anisotropic);
    return MicrofacetDistribution(MicrofacetType::GGX, std::max(0.001f, r2 / aspect), std::max(0.001f, r2 * aspect));
}
// The diffuse lobe's shape, times c / pi: Burley's (1 - Fi/2)(1 - Fo/2) with retro-reflection,
// lerped towards Hanrahan-Krueger's flattened shape by `flatness` (cos_i, cos_o > 0; cos_d =
// wo.h).
inline float diffuse_shape(float cos_i, float cos_o, float cos_d, float roughness, float flatness) {
    const float Fo = schlick_weight(cos_o), Fi = schlick_weight(cos_i);
    const float Rr = 2 * roughness * cos_d * cos_d;
    float shape = (1 - 0.5f * Fi) * (1 - 0.5f * Fo) + Rr * (Fo + Fi + Fo * Fi * (Rr - 1));
    if (flatness > 0) {  // Hanrahan-Krueger's fake subsurface, as Burley's
        const float Fss90 = Rr / 2, Fss = (1 + (Fss90 - 1) * Fo) * (1 + (Fss90 - 1) * Fi);
        const float f_ss = 1.25f * (Fss * (1 / (cos_o + cos_i) - 0.5f) + 0.5f);
        shape += (f_ss - shape) * flatness;
    }
    return shape;
}

}  // namespace disney

struct PrincipledMaterial {
    Rgb base_color{0.5f};
    float roughness = 0.5f, anisotropic = 0, metallic = 0, spec_trans = 0, spec_tint = 0, sheen = 0, sheen_tint = 0,
          clearcoat = 0, clearcoat_gloss = 0, flatness = 0;
    float eta = 1.5f;
    float rate_specular = 1, rate_clearcoat = 1, rate_diffuse = 1;  // the sampling rates
    bool transmits = false;  // spec_trans was given and is not 0 (a texture: its largest value)

    // The parameters textures may give (ParamInfo::texture_slot).
    enum Slot : int {
        kSlotBaseColor, kSlotRoughness, kSlotAnisotropic, kSlotMetallic, kSlotSpecTrans, kSlotSpecTint,
        kSlotSheen, kSlotSheenTint, kSlotClearcoat, kSlotClearcoatGloss, kSlotFlatness,
    };
    void set_texel(int slot, const Rgb& v) {
        if (slot == kSlotBaseColor) {
            base_color = v;
            return;
        }
        float* const fields[] = {nullptr, &roughness, &anisotropic, &metallic, &spec_trans, &spec_tint,
                                 &sheen, &sheen_tint, &clearcoat, &clearcoat_gloss, &flatness};
        if (slot > 0 && slot <= kSlotFlatness) *fields[slot] = v.x;
    }

    // f(wi, wo) = a + b c + c_sqrt sqrt(c), c the base colour (see the header comment).
    struct Terms {
        float a = 0, b = 0, c_sqrt = 0;
        template <class Colour>
        Colour value(const Colour& base, const Colour& sqrt_base) const {
            return Colour(a) + base * b + sqrt_base * c_sqrt;
        }
    };

    MicrofacetDistribution specular_distribution() const { return disney::specular_distribution(roughness, anisotropic); }
    // The selection probabilities of the lobes for wi (cos_i = |wi.z|, front: wi.z > 0).
    struct LobeChoice {
        float specular = 0, transmission = 0, clearcoat = 0, diffuse = 0;
    };
    // The weight of the transmission, bsdf = (1 - metallic) spec_trans (0 without spec_trans).
    float transmission_weight() const { return transmits ? (1 - metallic) * spec_trans : 0.0f; }
    LobeChoice lobe_choice(float cos_i, bool front) const {
        const float bsdf = transmission_weight();
        LobeChoice p;
        if (front) {
            const float F = fresnel_dielectric(cos_i, eta);
            p.specular = rate_specular * (1 - bsdf * (1 - F));
            p.transmission = rate_specular * bsdf * (1 - F);
            p.clearcoat = 0.25f * clearcoat * rate_clearcoat;
            p.diffuse = (1 - metallic) * (1 - spec_trans) * rate_diffuse;
        } else {
            if (!(bsdf > 0)) return p;
            const float F = fresnel_dielectric(cos_i, 1 / eta);
            p.specular = F;
            p.transmission = 1 - F;
        }
        const float total = p.specular + p.transmission + p.clearcoat + p.diffuse;
        if (!(total > 0)) return LobeChoice{};
        p.specular /= total, p.transmission /= total, p.clearcoat /= total, p.diffuse /= total;
        return p;
    }

    Terms terms(const Vec3f& wi_in, const Vec3f& wo_in, float& pdf) const;

    Rgb eval_and_pdf(const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        const Terms t = terms(wi, wo, pdf);
        return t.value(base_color, Rgb(std::sqrt(base_color.x), std::sqrt(base_color.y), std::sqrt(base_color.z)));
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

private:
    float schlick_weight_front(float cos) const { return disney::schlick_weight_front(cos, eta); }
    // GTR1 (the clearcoat's normal distribution) and its Smith masking with alpha 0.25.
    static float gtr1(float cos_h, float alpha) {
        const float a2 = alpha * alpha;
        const float d = (a2 - 1) / (kPi * std::log(a2) * (1 + (a2 - 1) * cos_h * cos_h));
        return d * cos_h > 1e-20f ? d : 0.0f;
    }
    static float clearcoat_g1(const Vec3f& v) {
        static const MicrofacetDistribution masking(MicrofacetType::GGX, 0.25f, 0.25f);
        return masking.G1(v);
    }
    float clearcoat_alpha() const { return 0.1f + (0.001f - 0.1f) * clearcoat_gloss; }
};

inline PrincipledMaterial::Terms PrincipledMaterial::terms(const Vec3f& wi_in, const Vec3f& wo_in, float& pdf) const {
    pdf = 0;
    Terms t;
    if (wi_in.z == 0 || wo_in.z == 0) return t;
    // Work with wi above the surface: from behind, mirror both directions; the relative index
    // is then 1 / eta.
    const bool front = wi_in.z > 0;
    const Vec3f wi = front ? wi_in : Vec3f(wi_in.x, wi_in.y, -wi_in.z);
    const Vec3f wo = front ? wo_in : Vec3f(wo_in.x, wo_in.y, -wo_in.z);
    const float e = front ? eta : 1 / eta;
    const float bsdf = transmission_weight(), brdf = (1 - metallic) * (1 - spec_trans);
    const LobeChoice p = lobe_choice(wi.z, front);
    const MicrofacetDistribution dist = specular_distribution();
    const float lum = luminance(base_color);
    // A multiple k of c / lum(c) (the tints): to b, or to a where lum is 0 (the tint is then 1).
    const auto add_tint = [&](float k) { (lum > 0 ? t.b : t.a) += lum > 0 ? k / lum : k; };

    if (wo.z > 0) {  // reflection
        const Vec3f h = normalize(wi + wo);
        const float ci = dot(wi, h), co = dot(wo, h);
        if (p.diffuse > 0) pdf += p.diffuse * cosine_hemisphere_pdf(wo);
        if (ci > 0 && co > 0) {
            const float D = dist.D(h), G = dist.G2(wi, wo), F_d = fresnel_dielectric(ci, e);
            const float k = D * G / (4 * wi.z * wo.z);
            if (front) {
                const float w = schlick_weight_front(ci), R0 = disney::schlick_r0(eta);
                t.a += k * ((1 - metallic) * (1 - spec_tint) * F_d + metallic * w + (1 - metallic) * spec_tint * w);
                t.b += k * metallic * (1 - w);
                add_tint(k * (1 - metallic) * spec_tint * (1 - w) * R0);
            } else {
                t.a += k * bsdf * F_d;
            }
            const float jacobian = 1 / (4 * co);
            pdf += p.specular * dist.pdf(wi, h) * jacobian;
            if (front && clearcoat > 0) {
                const float alpha = clearcoat_alpha(), Dcc = gtr1(h.z, alpha);
                const float Fcc = 0.04f + 0.96f * schlick_weight_front(ci);
                t.a += 0.25f * clearcoat * Fcc * Dcc * clearcoat_g1(wi) * clearcoat_g1(wo);
                pdf += p.clearcoat * Dcc * h.z * jacobian;
            }
        }
        if (front && brdf > 0) {
            const float cos_d = dot(h, wo);
            t.b += brdf * kInvPi * disney::diffuse_shape(wi.z, wo.z, cos_d, roughness, flatness);
            if (sheen > 0 && metallic < 1) {
                const float s = sheen * (1 - metallic) * disney::schlick_weight(std::abs(cos_d));
                t.a += s * (1 - sheen_tint);
                add_tint(s * sheen_tint);
            }
        }
        return t;
    }
    // Transmission: roughdielectric's refraction lobe between the indices 1 and eta (eta and 1
    // from behind), times bsdf sqrt(c).
    if (!(bsdf > 0)) return t;
    t.c_sqrt = bsdf * microfacet_refraction(dist, wi, wo, front ? 1.0f : eta, front ? eta : 1.0f, p.transmission, pdf);
    return t;
}

inline std::optional<BsdfSample> PrincipledMaterial::sample(const Vec3f& wi_in, Vec2f u) const {
    if (wi_in.z == 0) return std::nullopt;
    const bool front = wi_in.z > 0;
    const Vec3f wi(wi_in.x, wi_in.y, std::abs(wi_in.z));
    const LobeChoice p = lobe_choice(wi.z, front);
    // The lobe, and u.x rescaled to [0, 1) within its share.
    const float shares[4] = {p.diffuse, p.clearcoat, p.transmission, p.specular};
    int lobe = 0;
    float start = 0;
    while (lobe < 3 && !(u.x < start + shares[lobe])) start += shares[lobe++];
    if (!(shares[lobe] > 0)) return std::nullopt;
    u.x = std::min((u.x - start) / shares[lobe], 0x1.fffffep-1f);
    Vec3f wo;
    uint32_t flags = kLobeGlossy | kLobeReflection;
    if (lobe == 0) {
        wo = square_to_cosine_hemisphere(u);
        flags = kLobeDiffuse | kLobeReflection;
    } else if (lobe == 1) {
        // GTR1's normals, cos^2 theta = (1 - alpha^2^(1 - u)) / (1 - alpha^2), density D cos.
        const float a2 = clearcoat_alpha() * clearcoat_alpha();
        const float cos2 = (1 - std::pow(a2, 1 - u.y)) / (1 - a2), sin_t = std::sqrt(std::max(0.0f, 1 - cos2));
        const float phi = 2 * kPi * u.x;
        const Vec3f m(std::cos(phi) * sin_t, std::sin(phi) * sin_t, std::sqrt(std::max(0.0f, cos2)));
        if (!(dot(wi, m) > 0)) return std::nullopt;
        wo = reflect(wi, m);
    } else {
        const Vec3f m = specular_distribution().sample(wi, u);
        const float c = dot(wi, m);
        if (!(c > 0)) return std::nullopt;
        if (lobe == 3) {
            wo = reflect(wi, m);
        } else {
            if (!refract_about(wi, m, front ? eta : 1 / eta, wo)) return std::nullopt;  // total internal reflection at m
            flags = kLobeGlossy | kLobeTransmission;
        }
    }
    if (lobe == 2 ? wo.z >= 0 : wo.z <= 0) return std::nullopt;
    if (!front) wo.z = -wo.z;
    float pdf;
    const Rgb f = eval_and_pdf(wi_in, wo, pdf);
    if (!(pdf > 0)) return std::nullopt;
    return BsdfSample{wo, f, pdf, false, flags};
}

inline const PluginInfo& principled_plugin() {
    using S = PrincipledMaterial::Slot;
    static const PluginInfo info{
        "bsdf",
        "principled",
        "the Disney BSDF as Mitsuba 3 defines it: metallic, specular, clearcoat, sheen, anisotropy, specular transmission",
        {{"base_color", ParamType::Rgb, "0.5", "base colour c", "", S::kSlotBaseColor},
         {"roughness", ParamType::Float, "0.5", "0 (smooth) to 1", "", S::kSlotRoughness},
         {"anisotropic", ParamType::Float, "0", "0 to 1: stretches the highlight along dp/du", "", S::kSlotAnisotropic},
         {"metallic", ParamType::Float, "0", "0 (dielectric) to 1 (metal of colour c)", "", S::kSlotMetallic},
         {"spec_trans", ParamType::Float, "0", "0 to 1: the share of rough refraction (glass)", "", S::kSlotSpecTrans},
         {"spec_tint", ParamType::Float, "0", "0 to 1: tints the dielectric specular towards c", "", S::kSlotSpecTint},
         {"sheen", ParamType::Float, "0", "retro-reflective grazing sheen (cloth), not negative", "", S::kSlotSheen},
         {"sheen_tint", ParamType::Float, "0", "0 to 1: tints the sheen towards c", "", S::kSlotSheenTint},
         {"clearcoat", ParamType::Float, "0", "0 to 1: a second, white specular lobe (GTR1)", "", S::kSlotClearcoat},
         {"clearcoat_gloss", ParamType::Float, "0", "0 (clearcoat alpha 0.1) to 1 (0.001)", "", S::kSlotClearcoatGloss},
         {"flatness", ParamType::Float, "0", "0 to 1: flattens the diffuse lobe (fake subsurface)", "", S::kSlotFlatness},
         {"specular", ParamType::Float, "0.5", "R0 = 0.08 specular: eta = 2 / (1 - sqrt(0.08 specular)) - 1 (not with eta)"},
         {"eta", ParamType::Float, "", "relative index of refraction (instead of specular)"},
         {"main_specular_sampling_rate", ParamType::Float, "1", "factor of the specular lobes' sampling probability"},
         {"clearcoat_sampling_rate", ParamType::Float, "1", "factor of the clearcoat's sampling probability"},
         {"diffuse_reflectance_sampling_rate", ParamType::Float, "1", "factor of the diffuse lobe's sampling probability"}}};
    return info;
}

inline PrincipledMaterial read_principled(Properties& p) {
    PrincipledMaterial m;
    m.base_color = p.get_rgb("base_color");
    const auto unit = [&](const char* name) {
        const float v = p.get_float(name);
        if (!(v >= 0 && v <= 1)) p.fail(name, fmt::format("{} must be between 0 and 1, got {}", name, v));
        return v;
    };
    m.roughness = unit("roughness");
    m.anisotropic = unit("anisotropic");
    m.metallic = unit("metallic");
    m.spec_trans = unit("spec_trans");
    m.spec_tint = unit("spec_tint");
    m.sheen_tint = unit("sheen_tint");
    m.clearcoat = unit("clearcoat");
    m.clearcoat_gloss = unit("clearcoat_gloss");
    m.flatness = unit("flatness");
    m.sheen = p.get_float("sheen");
    if (!(m.sheen >= 0 && m.sheen < 1e6f)) p.fail("sheen", fmt::format("sheen must not be negative, got {}", m.sheen));
    m.transmits = m.spec_trans > 0;
    if (p.has("eta") && p.has("specular")) p.fail("eta", "give either eta or specular, not both (each sets the other)");
    if (p.has("eta")) {
        m.eta = p.get_float("eta");
        if (!(m.eta > 0 && m.eta < 100)) p.fail("eta", fmt::format("eta must be positive, got {}", m.eta));
        if (m.transmits && m.eta == 1) m.eta = 1.001f;  // as Mitsuba: an index of 1 transmits nothing visible
    } else {
        float s = p.get_float("specular");
        if (!(s >= 0 && s < 12.5f)) p.fail("specular", fmt::format("specular must be at least 0 and below 12.5, got {}", s));
        if (m.transmits && s == 0) s = 1e-3f;  // as Mitsuba: eta 1 is not plausible for transmission
        m.eta = 2 / (1 - std::sqrt(0.08f * s)) - 1;
    }
    const auto rate = [&](const char* name) {
        const float v = p.get_float(name);
        if (!(v > 0 && v < 1e6f)) p.fail(name, fmt::format("{} must be positive, got {} (a lobe never sampled would be missed)", name, v));
        return v;
    };
    m.rate_specular = rate("main_specular_sampling_rate");
    m.rate_clearcoat = rate("clearcoat_sampling_rate");
    m.rate_diffuse = rate("diffuse_reflectance_sampling_rate");
    return m;
}

}  // namespace pathlab
