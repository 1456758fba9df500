// roughplastic: a diffuse base under a rough dielectric coating. The coating reflects like a
// rough dielectric interface (microfacet reflection, microfacet.hpp) and lets the rest through
// to the diffuse base as plastic.hpp does:
//   f(wi, wo) = R_s F(wi.h) D(h) G2(wi, wo) / (4 cos_i cos_o)
//             + rho' (1 - F(cos_i)) (1 - F(cos_o)) / (pi eta^2)
// where the diffuse part's transmission through the coating uses the Fresnel term of the
// macro surface (the approximation of Mitsuba 0.4's roughplastic; Mitsuba 3 tabulates the
// rough coating's transmittance instead). rho' and eta as in plastic.hpp. Reciprocal; its
// albedo stays below 1 (tested) but is not exactly 1 for a white base.
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
// Sampling: the coating's lobe with probability P_s (as plastic.hpp, from the macro Fresnel
// term), else the cosine-weighted hemisphere; pdf() is the mixture of both densities and f
// the whole BSDF, so every sample is an ordinary (non-delta) one.
#pragma once

#include <optional>

#include "core/sampling.hpp"
#include "scene/bsdf_sample.hpp"
#include "scene/microfacet.hpp"
#include "scene/plastic.hpp"

namespace pathlab {

struct RoughPlasticMaterial {
    MicrofacetDistribution distribution;
    CoatedDiffuse coat;

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
        const float Fi = coat.fresnel(wi.z), ps = coat.specular_probability(Fi);
        Rgb f = coat.diffuse(Fi, wo.z);
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
        const float ps = coat.specular_probability(coat.fresnel(wi.z));
        Vec3f wo;
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
        return BsdfSample{wo, f, p, false};
    }
};

}  // namespace pathlab
