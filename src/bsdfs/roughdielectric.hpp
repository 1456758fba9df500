// roughdielectric: a rough interface between two dielectrics (frosted glass), the microfacet
// BSDF of Walter et al. 2007 with reflection and refraction on each microfacet:
//   reflection  f = F D G2 / (4 |cos_i| |cos_o|),            h = normalize(wi + wo)
//   refraction  f = (1 - F) D G2 |wi.h| |wo.h| eta_i^2 / (|cos_i| |cos_o| (eta_i wi.h + eta_o wo.h)^2),
//               h = normalize(eta_i wi + eta_o wo)
// with F = F(wi.h) the dielectric Fresnel term, eta_i / eta_o the indices on the sides of wi
// and wo, and h turned to the side of the normal.
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   distribution      string          ggx or beckmann                                  default beckmann
//   alpha             float           roughness (isotropic)                            default 0.1
//   alpha_u, alpha_v  float           anisotropic roughness (instead of alpha)
//   int_ior           float or string interior index of refraction, or a name          default bk7 (1.5046)
//   ext_ior           float or string exterior index of refraction                     default air (1.000277)
//   sellmeier_b/_c, cauchy, int_ior="bk7-sellmeier" or "fused silica": a dispersive interior index,
//                     as dielectric's (spectral mode refracts each path's hero wavelength with it)
//   sample_visible    boolean         accepted for compatibility; visible normals are always sampled
// Like dielectric, it cannot be wrapped in twosided: both of its sides matter.
//
// Radiance convention (as dielectric.hpp): light flows from wo to wi, and radiance keeps
// L / eta^2 invariant, hence eta_i^2 in the refraction term; the BSDF satisfies
// f(wi, wo) / eta_i^2 = f(wo, wi) / eta_o^2, and a refracted sample's weight is
// (1 - F) (eta_i / eta_o)^2 G2 / G1(wi) / P(refraction).
//
// Sampling: reflection is chosen with probability P_R = F(|cos_i|) (the Fresnel term of the
// macro surface, kept within [0.05, 0.95] so that neither lobe is starved), refraction with
// 1 - P_R; then a microfacet normal h from microfacet.hpp, and wo reflected or refracted
// about it. Directions on the wrong side, and refraction beyond the critical angle of h, are
// rejected (no sample). pdf() is the mixture of both lobes' densities.
#pragma once

#include <algorithm>
#include <optional>

#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/microfacet.hpp"
#include "bsdfs/dielectric.hpp"

namespace pathlab {

// The refraction term above for wi above the surface and wo below it, with the indices eta_i on
// wi's side and eta_o on wo's, and in `pdf` its density when wo is sampled with probability
// `lobe_probability` by refracting wi about a normal drawn from D_wi (both 0 where no normal
// refracts wi into wo). Also principled's transmission (principled.hpp).
inline float microfacet_refraction(const MicrofacetDistribution& distribution, const Vec3f& wi, const Vec3f& wo, float eta_i,
                                   float eta_o, float lobe_probability, float& pdf) {
    pdf = 0;
    Vec3f h = wi * eta_i + wo * eta_o;
    const float len = length(h);
    if (!(len > 0)) return 0.0f;
    h = h / len;
    if (h.z < 0) h = -h;
    const float ci = dot(wi, h), co = dot(wo, h);
    if (!(ci > 0) || !(co < 0)) return 0.0f;  // wi must see the facet's front, wo its back
    const float D = distribution.D(h);
    if (!(D > 0)) return 0.0f;
    // F from the side of the lower index, where it is well conditioned, so that eval()
    // gives the same value whichever of wi and wo comes first (the same cosine is used).
    const float eta = eta_o / eta_i;
    const float F = eta >= 1 ? fresnel_dielectric(ci, eta) : fresnel_dielectric(-co, 1 / eta);
    const float den = eta_i * ci + eta_o * co;
    if (!(den * den > 0)) return 0.0f;
    const float den2 = den * den;
    pdf = lobe_probability * distribution.pdf(wi, h) * eta_o * eta_o * -co / den2;
    return (1 - F) * D * distribution.G2(wi, wo) * ci * -co * eta_i * eta_i / (wi.z * -wo.z * den2);
}

// wi (above the surface) refracted about the microfacet normal m (wi.m > 0) into the side of
// relative index eta = eta_o / eta_i; false at total internal reflection.
inline bool refract_about(const Vec3f& wi, const Vec3f& m, float eta, Vec3f& wo) {
    const float c = dot(wi, m);
    float cos_t;
    if (fresnel_dielectric(c, eta, &cos_t) >= 1) return false;
    const float r = 1 / eta;
    wo = normalize(-wi * r + m * (r * c - cos_t));
    return true;
}

struct RoughDielectricMaterial {
    MicrofacetDistribution distribution;
    float int_ior = 1.5046f;
    float ext_ior = 1.000277f;
    // A dispersive interior index, as dielectric's (dielectric.hpp): int_ior is then its n_d.
    std::shared_ptr<const Ior> dispersion = nullptr;

    // Probability of sampling reflection, given |cos_i| and eta = eta_o / eta_i.
    static float reflection_probability(float cos_i, float eta) {
        return std::clamp(fresnel_dielectric(cos_i, eta), 0.05f, 0.95f);
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

    Rgb eval_and_pdf(Vec3f wi, Vec3f wo, float& pdf) const {
        pdf = 0;
        if (wi.z == 0 || wo.z == 0) return Rgb(0.0f);
        // Work with wi above the surface: from inside, mirror both directions (D and Lambda
        // are even in z) and swap the indices.
        const bool outside = wi.z > 0;
        const float eta_i = outside ? ext_ior : int_ior, eta_o = outside ? int_ior : ext_ior;
        if (!outside) wi.z = -wi.z, wo.z = -wo.z;
        const float eta = eta_o / eta_i;
        const float p_reflect = reflection_probability(wi.z, eta);
        if (wo.z > 0) {
            const Vec3f h = normalize(wi + wo);
            const float c = dot(wi, h), D = distribution.D(h);
            if (!(c > 0) || !(D > 0)) return Rgb(0.0f);
            const float F = fresnel_dielectric(c, eta);
            pdf = p_reflect * distribution.pdf(wi, h) / (4 * c);
            return Rgb(F * D * distribution.G2(wi, wo) / (4 * wi.z * wo.z));
        }
        return Rgb(microfacet_refraction(distribution, wi, wo, eta_i, eta_o, 1 - p_reflect, pdf));
    }

    std::optional<BsdfSample> sample(const Vec3f& wi_in, Vec2f u) const {
        if (wi_in.z == 0) return std::nullopt;
        const bool outside = wi_in.z > 0;
        const float eta_i = outside ? ext_ior : int_ior, eta_o = outside ? int_ior : ext_ior;
        const Vec3f wi(wi_in.x, wi_in.y, std::abs(wi_in.z));
        const float eta = eta_o / eta_i;
        const float p_reflect = reflection_probability(wi.z, eta);
        const bool reflect_lobe = u.x < p_reflect;
        u.x = reflect_lobe ? u.x / p_reflect : std::min((u.x - p_reflect) / (1 - p_reflect), 0x1.fffffep-1f);
        const Vec3f h = distribution.sample(wi, u);
        const float c = dot(wi, h);
        if (!(c > 0)) return std::nullopt;
        Vec3f wo;
        if (reflect_lobe) {
            wo = reflect(wi, h);
            if (wo.z <= 0) return std::nullopt;
        } else {
            if (!refract_about(wi, h, eta, wo)) return std::nullopt;  // total internal reflection at h
            if (wo.z >= 0) return std::nullopt;
        }
        if (!outside) wo.z = -wo.z;
        float p;
        const Rgb f = eval_and_pdf(wi_in, wo, p);
        if (!(p > 0)) return std::nullopt;
        return BsdfSample{wo, f, p, false, kLobeGlossy | (reflect_lobe ? kLobeReflection : kLobeTransmission)};
    }

    // A texture may give the roughness (microfacet.hpp's slots).
    void set_texel(int slot, const Rgb& v) { distribution.set_texel(slot, v.x); }
};

inline const PluginInfo& roughdielectric_plugin() {
    static const PluginInfo info = [] {
        PluginInfo i{"bsdf", "roughdielectric", "a rough interface between two dielectrics (frosted glass): Walter et al. 2007",
                     microfacet_params(true, true)};
        const PluginInfo& smooth = dielectric_plugin();  // int_ior with the dispersive names, ext_ior, sellmeier_b/_c, cauchy
        i.params.insert(i.params.end(), smooth.params.begin(), smooth.params.end());
        i.params.push_back(kSampleVisibleParam);
        return i;
    }();
    return info;
}
inline RoughDielectricMaterial read_roughdielectric(Properties& p) {
    const MicrofacetDistribution d = read_microfacet(p, /*anisotropic=*/true);
    const float ext_ior = read_ior(p, "ext_ior");
    auto dispersion = read_dispersion(p);
    const float int_ior = dispersion ? float((*dispersion)(kDispersionReferenceWavelength)) : read_ior(p, "int_ior");
    if (int_ior == ext_ior) p.fail("int_ior and ext_ior are equal: the interface would be invisible");
    p.get_bool("sample_visible");
    return RoughDielectricMaterial{d, int_ior, ext_ior, std::move(dispersion)};
}

}  // namespace pathlab
