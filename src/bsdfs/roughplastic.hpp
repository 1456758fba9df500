// roughplastic: a diffuse base under a rough dielectric coating. The coating reflects like a
// rough dielectric interface (microfacet reflection, microfacet.hpp); what it does not reflect
// reaches the diffuse base, as in plastic.hpp, and leaves through the coating again:
//   f(wi, wo) = R_s F(wi.h) D(h) G2(wi, wo) / (4 cos_i cos_o)
//             + rho' T(cos_i) T(cos_o) / (pi eta^2)
// T(mu) = 1 - E(mu) is the coating's transmittance, E(mu) the directional albedo of its
// reflection lobe (with R_s = 1), tabulated once per material by quadrature (as Mitsuba 3
// does). rho' = rho / (1 - Fdr) (or rho / (1 - rho Fdr) when nonlinear) with the coating's
// internal diffuse reflectance taken as Fdr = 1 - (2 / eta^2) integral_0^1 T(mu) mu dmu, the
// value that reciprocity gives the rough interface from inside; so a white base (rho = 1,
// R_s = 1, linear) reflects E(cos_i) + T(cos_i) = 1 at every angle. Reciprocal.
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
// Sampling: the coating's lobe with probability P_s (as plastic.hpp, with E(cos_i) in place
// of the smooth Fresnel term), else the cosine-weighted hemisphere; pdf() is the mixture of
// both densities and f the whole BSDF, so every sample is an ordinary (non-delta) one.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

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
            transmittance[size_t(k)] = float(1 - coating_albedo(std::max(1e-4, double(k) / (kTableSize - 1))));
        // Fdr = 1 - (2 / eta^2) integral of T(mu) mu dmu (trapezoidal on the table's nodes).
        double integral = 0;
        for (int k = 0; k + 1 < kTableSize; ++k) {
            const double m0 = double(k) / (kTableSize - 1), m1 = double(k + 1) / (kTableSize - 1);
            integral += 0.5 * (transmittance[size_t(k)] * m0 + transmittance[size_t(k + 1)] * m1) * (m1 - m0);
        }
        coat.fdr = float(1 - 2 * integral / (double(coat.eta) * coat.eta));
        coat.update();
    }

    // T(mu), linearly interpolated.
    float T(float mu) const {
        const float x = std::clamp(mu, 0.0f, 1.0f) * (kTableSize - 1);
        const int k = std::min(int(x), kTableSize - 2);
        const float t = x - float(k);
        return transmittance[size_t(k)] * (1 - t) + transmittance[size_t(k + 1)] * t;
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
    // E(mu): albedo of the coating's reflection (R_s = 1) for light arriving at cosine mu, by
    // the midpoint rule over microfacet normals with theta_h = atan(a tan(pi t / 2)), t
    // uniform, which puts the nodes where D has its mass.
    double coating_albedo(double mu, int n = 64) const {
        const Vec3f wi(float(std::sqrt(1 - mu * mu)), 0.0f, float(mu));
        const double a = std::sqrt(double(distribution.alpha_u) * distribution.alpha_v);
        double sum = 0;
        for (int i = 0; i < n; ++i) {
            const double x = std::tan(M_PI / 2 * (i + 0.5) / n), theta = std::atan(a * x);
            const double dtheta = a * (M_PI / 2) * (1 + x * x) / (1 + a * a * x * x);
            const double st = std::sin(theta), ct = std::cos(theta);
            for (int j = 0; j < n; ++j) {
                const double phi = 2 * M_PI * (j + 0.5) / n;
                const Vec3f h(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
                const float c = dot(wi, h);
                if (c <= 0) continue;
                const Vec3f wo = reflect(wi, h);
                if (wo.z <= 0) continue;
                // f cos_o d omega_o = F D G2 / (4 mu wo.z) wo.z 4 (wo.h) d omega_h
                sum += double(coat.fresnel(c)) * distribution.D(h) * distribution.G2(wi, wo) * c / mu * st * dtheta;
            }
        }
        return sum * (2 * M_PI / n) / n;
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
