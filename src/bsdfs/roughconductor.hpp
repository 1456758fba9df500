// roughconductor: a rough metal, the Cook-Torrance / Walter et al. 2007 microfacet BRDF with
// the Fresnel reflectance of a conductor,
//   f(wi, wo) = R F(wi.h) D(h) G2(wi, wo) / (4 cos_i cos_o),   h = normalize(wi + wo).
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   distribution          string  ggx or beckmann                                  default beckmann
//   alpha                 float   roughness (isotropic)                            default 0.1
//   alpha_u, alpha_v      float   anisotropic roughness along the tangent and bitangent (instead of alpha)
//   material              string  a metal by name: none, Au, Ag, Cu, Al, Cr, a-C   default none
//   eta, k                rgb     complex index of refraction, instead of material default 0, 1
//   specular_reflectance  rgb     R, scales the reflectance (not physical)         default 1
//   sample_visible        boolean accepted for compatibility; visible normals are always sampled
// material="none" (eta = 0, k = 1) has F = 1: only shadowing-masking loses energy (the
// single-scattering loss of the microfacet model). One-sided unless wrapped in twosided.
//
// Sampling: a microfacet normal h visible from wi (microfacet.hpp), wo the
// mirror of wi about h; directions below the surface are rejected (no sample). The density
// of wo is pdf_h(h) / (4 wi.h); the weight f cos / pdf is R F G2 / G1(wi).
#pragma once

#include <optional>

#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/microfacet.hpp"
#include "bsdfs/ior.hpp"

namespace pathlab {

struct RoughConductorMaterial {
    MicrofacetDistribution distribution;
    Rgb eta{0.0f}, k{1.0f};
    Rgb specular_reflectance{1.0f};
    const MeasuredConductor* measured = nullptr;  // spectral mode's eta, k of a named metal (ior.hpp)

    Rgb eval(const Vec3f& wi, const Vec3f& wo) const {
        float unused;
        return eval_and_pdf(wi, wo, unused);
    }
    float pdf(const Vec3f& wi, const Vec3f& wo) const {
        float p;
        eval_and_pdf(wi, wo, p);
        return p;
    }
    Rgb eval_and_pdf(const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        pdf = 0;
        if (wi.z <= 0 || wo.z <= 0) return Rgb(0.0f);
        const Vec3f sum = wi + wo;
        const float len = length(sum);
        if (!(len > 0)) return Rgb(0.0f);
        const Vec3f h = sum / len;
        const float cos_ih = dot(wi, h);  // = dot(wo, h) > 0 since both are above the surface
        const float D = distribution.D(h);
        if (!(D > 0) || !(cos_ih > 0)) return Rgb(0.0f);
        pdf = distribution.pdf(wi, h) / (4 * cos_ih);
        const float G = distribution.G2(wi, wo);
        return specular_reflectance * fresnel_conductor(cos_ih, eta, k) * (D * G / (4 * wi.z * wo.z));
    }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        if (wi.z <= 0) return std::nullopt;
        const Vec3f h = distribution.sample(wi, u);
        const Vec3f wo = reflect(wi, h);
        if (wo.z <= 0) return std::nullopt;
        float p;
        const Rgb f = eval_and_pdf(wi, wo, p);
        if (!(p > 0)) return std::nullopt;
        return BsdfSample{wo, f, p, false, kLobeGlossy | kLobeReflection};
    }

    // The parameters a texture may give: the reflectance, or the roughness (microfacet.hpp).
    static constexpr int kSlotSpecularReflectance = 0;
    void set_texel(int slot, const Rgb& v) {
        if (slot == kSlotSpecularReflectance) specular_reflectance = v;
        else distribution.set_texel(slot, v.x);
    }
};

inline const PluginInfo& roughconductor_plugin() {
    static const PluginInfo info = [] {
        PluginInfo i{"bsdf", "roughconductor", "a rough metal: Cook-Torrance / Walter et al. microfacet reflection",
                     microfacet_params(true, true)};
        i.params.insert(i.params.end(), {kConductorMaterialParam, kConductorEtaParam, kConductorKParam,
                                         {"specular_reflectance", ParamType::Rgb, "1", "scales the reflectance (not physical)",
                                          "specularReflectance", RoughConductorMaterial::kSlotSpecularReflectance},
                                         kSampleVisibleParam});
        return i;
    }();
    return info;
}
inline RoughConductorMaterial read_roughconductor(Properties& p) {
    const MicrofacetDistribution d = read_microfacet(p, /*anisotropic=*/true);
    const ComplexIor ior = read_conductor_ior(p);
    p.get_bool("sample_visible");
    return RoughConductorMaterial{d, ior.eta, ior.k, p.get_rgb("specular_reflectance"), ior.measured};
}

}  // namespace pathlab
