// roughplastic: a diffuse base under a rough dielectric coating, as Mitsuba 3 defines it
// (src/bsdfs/roughplastic.cpp there). The coating reflects like a rough dielectric interface
// (microfacet reflection, microfacet.hpp); what it transmits reaches the diffuse base, as in
// plastic.hpp, and leaves through the coating again:
//   f(wi, wo) = R_s F(wi.h) D(h) G2(wi, wo) / (4 cos_i cos_o)
//             + rho' T(cos_i) T(cos_o) / (pi eta^2)
// T(mu) is the coating's transmittance for light arriving at cosine mu: the albedo of the rough
// dielectric's (single-scattering) refraction lobe, integral (1 - F(wi.m)) G1(wt) over the
// visible normals m (wt the refracted direction). rho' = rho / (1 - Fint) (or rho / (1 - rho
// Fint) when nonlinear), with Fint = 2 integral_0^1 R_in(mu) mu dmu the coating's reflectance for
// diffuse light from inside, R_in(mu) the albedo of its reflection lobe at relative index
// 1 / eta (total internal reflection included). Both are tabulated once per material by
// quadrature over the visible normals, as Mitsuba 3 does. The single-scattering lobes lose the
// energy of the facets' inter-reflections, so a white base reflects less than it receives
// (0.55 at normal incidence with GGX alpha 0.5: docs/materials.md). This is Mitsuba's model;
// pathlab's before 2026-12-05 took T = 1 - E and Fint from reciprocity, a lossless model 6-20%
// brighter than Mitsuba's render tests. Reciprocal.
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   distribution          string           ggx or beckmann                          default beckmann
//   alpha                 float            roughness of the coating (isotropic)     default 0.1
//   diffuse_reflectance   rgb              rho, the base's albedo                   default 0.5
//   specular_reflectance  rgb              R_s, scales the coating's reflection     default 1
//   int_ior               float or string  coating index, or a name                 default polypropylene (1.49)
//   ext_ior               float or string  exterior index                           default air (1.000277)
//   nonlinear             boolean          see plastic.hpp                          default false
//   sample_visible        boolean          accepted; visible normals are always sampled
// One-sided unless wrapped in twosided.
//
// Sampling: the coating's lobe with probability P_s (as plastic.hpp, with 1 - T(cos_i) in
// place of the smooth Fresnel term), else the cosine-weighted hemisphere; pdf() is the mixture
// of both densities and f the whole BSDF, so every sample is an ordinary (non-delta) one.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "core/sampling.hpp"
#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/microfacet.hpp"
#include "bsdfs/plastic.hpp"

namespace pathlab {

struct RoughPlasticMaterial {
    static constexpr int kTableSize = 64;  // T at mu = k / (kTableSize - 1)

    MicrofacetDistribution distribution;
    CoatedDiffuse coat;  // coat.base uses the rough coating's Fdr (set by the constructor)
    std::array<float, kTableSize> transmittance{};

    RoughPlasticMaterial() = default;
    RoughPlasticMaterial(const MicrofacetDistribution& d, const CoatedDiffuse& c) : distribution(d), coat(c) {
        for (int k = 0; k < kTableSize; ++k)
            transmittance[size_t(k)] = float(coating_albedo(std::max(1e-4, double(k) / (kTableSize - 1)), coat.eta, false, 64));
        // Fint = 2 integral R_in(mu) mu dmu = integral R_in(sqrt(s)) ds: the midpoint rule in s = mu^2,
        // on either side of the smooth interface's critical angle (s_c = 1 - 1 / eta^2), where a
        // nearly smooth coating's R_in jumps to 1.
        constexpr int kNodes = 24;
        const double sc = coat.eta > 1 ? 1 - 1 / (double(coat.eta) * coat.eta) : 0.0;
        double sum = 0;
        for (const auto& [s0, s1] : {std::pair(0.0, sc), std::pair(sc, 1.0)})
            for (int k = 0; k < kNodes && s1 > s0; ++k)
                sum += (s1 - s0) / kNodes * coating_albedo(std::sqrt(s0 + (s1 - s0) * (k + 0.5) / kNodes), 1 / coat.eta, true, 96);
        coat.fdr = float(sum);
        coat.update();
    }

    // T(mu), linearly interpolated.
    float T(float mu) const { return lookup(transmittance, mu); }
    // A table over mu = k / (kTableSize - 1) at mu, linearly interpolated (T's, and its derivative's:
    // diff/bsdf_derivatives.hpp).
    static float lookup(const std::array<float, kTableSize>& table, float mu) {
        const float x = std::clamp(mu, 0.0f, 1.0f) * (kTableSize - 1);
        const int k = std::min(int(x), kTableSize - 2);
        const float t = x - float(k);
        return table[size_t(k)] * (1 - t) + table[size_t(k + 1)] * t;
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
    Rgb eval_and_pdf(const Vec3f& wi, const Vec3f& wo, float& pdf) const {
        pdf = 0;
        if (wi.z <= 0 || wo.z <= 0) return Rgb(0.0f);
        const float Ti = T(wi.z), ps = coat.specular_probability(1 - Ti);
        Rgb f = coat.base * (Ti * T(wo.z));
        pdf = (1 - ps) * cosine_hemisphere_pdf(wo);
        const Vec3f h = normalize(wi + wo);
        const float c = dot(wi, h), D = distribution.D(h);
        if (c > 0 && D > 0) {
            f += coat.specular_reflectance *
                 (coat.fresnel(c) * D * distribution.G2(wi, wo) / (4 * wi.z * wo.z));
            pdf += ps * distribution.pdf(wi, h) / (4 * c);
        }
        return f;
    }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        if (wi.z <= 0) return std::nullopt;
        const float ps = coat.specular_probability(1 - T(wi.z));
        Vec3f wo;
        const uint32_t lobe = kLobeReflection | (u.x < ps ? kLobeGlossy : kLobeDiffuse);
        if (u.x < ps) {
            u.x = u.x / ps;
            wo = reflect(wi, distribution.sample(wi, u));
        } else {
            u.x = std::min((u.x - ps) / (1 - ps), 0x1.fffffep-1f);
            wo = square_to_cosine_hemisphere(u);
        }
        if (wo.z <= 0) return std::nullopt;
        float p;
        const Rgb f = eval_and_pdf(wi, wo, p);
        if (!(p > 0)) return std::nullopt;
        return BsdfSample{wo, f, p, false, lobe};
    }

    // Textures may give the reflectances, not the roughness (the transmittance table depends on it).
    void set_texel(int slot, const Rgb& v) { coat.set_texel(slot, v); }
    void texels_changed() { coat.update(); }

private:
    // The coating's albedo for light arriving at cosine mu from the side where the relative
    // index is eta (eta_t / eta_i): of its reflection lobe (reflect) or its refraction lobe.
    // The midpoint rule on n x n points of the visible normals' sample space (each point a
    // visible normal m, of density D_wi), so that the integrand is F G1(wo) or (1 - F) G1(wt).
    double coating_albedo(double mu, float eta, bool reflect_lobe, int n) const {
        const Vec3f wi(float(std::sqrt(1 - mu * mu)), 0.0f, float(mu));
        double sum = 0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const Vec3f m = distribution.sample(wi, Vec2f(float((i + 0.5) / n), float((j + 0.5) / n)));
                const float c = dot(wi, m);
                if (!(c > 0)) continue;
                float cos_t = 0;
                const float F = fresnel_dielectric(c, eta, &cos_t);
                if (reflect_lobe) {
                    const Vec3f wo = reflect(wi, m);
                    if (wo.z > 0) sum += double(F) * distribution.G1(wo);
                } else if (F < 1) {
                    const Vec3f wt = (c / eta - cos_t) * m - wi / eta;  // refracted, below the surface
                    if (wt.z < 0) sum += double(1 - F) * distribution.G1(wt);
                }
            }
        return sum / (double(n) * n);
    }
};

inline const PluginInfo& roughplastic_plugin() {
    static const PluginInfo info = [] {
        PluginInfo i{"bsdf", "roughplastic", "a diffuse base under a rough dielectric coating", microfacet_params(false, false)};
        for (const ParamInfo& c : coated_diffuse_params()) i.params.push_back(c);
        i.params.push_back(kSampleVisibleParam);
        return i;
    }();
    return info;
}
inline RoughPlasticMaterial read_roughplastic(Properties& p) {
    const MicrofacetDistribution d = read_microfacet(p, /*anisotropic=*/false);
    const CoatedDiffuse coat = read_coated_diffuse(p);
    p.get_bool("sample_visible");
    return RoughPlasticMaterial(d, coat);
}

}  // namespace pathlab
