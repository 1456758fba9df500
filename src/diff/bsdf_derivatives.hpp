// Derivatives of the BSDF value f(wi, wo) with respect to a material's differentiable
// parameters (parameters.hpp): for each bound scalar parameter theta_j (one colour channel of a
// reflectance, or the Phong exponent, or the roughness alpha), the Rgb df/dtheta_j. The path
// replay (path_replay.cpp) weighs them with the adjoint radiance (reverse mode) or a tangent
// (forward mode). Sampling is detached (as Mitsuba 3's prb): no derivative of a pdf, a lobe's
// selection probability or a Russian roulette probability is taken.
//
// For a delta sample (conductor, plastic's coating) the derivative is that of the sample's
// coefficient f (bsdf_sample.hpp), for other samples that of eval(wi, wo).
//
// Formulas (directions local, both above the surface but for roughdielectric):
//   Phong:           df/drho_d = 1/pi,  df/drho_s = (n + 2) c^n / (2 pi),
//                    df/dn = rho_s c^n (1 + (n + 2) ln c) / (2 pi)     (c = cos alpha > 0)
//   roughconductor:  df/dR = F D G2 / (4 cos_i cos_o),  df/dalpha = R F (D' G2 + D G2') / (4 cos_i cos_o),
//                    G2 = G1(wi) G1(wo), G2' = -G2 (G1(wi) Lambda'(wi) + G1(wo) Lambda'(wo)), with for GGX
//                    D' = D (-2/alpha + 4 s / (alpha^3 t)), t = s / alpha^2 + hz^2, s = hx^2 + hy^2,
//                    Lambda' = a2 / (2 alpha sqrt(1 + a2)), a2 = alpha^2 tan^2;
//                    for Beckmann D' = D (2 s / (alpha^3 hz^2) - 2/alpha), Lambda' = exp(-c^2) / (2 sqrt(pi) c alpha), c = 1/sqrt(a2)
//   roughdielectric: df/dalpha = f (D'/D + G2'/G2) for reflection and refraction (wi on either side;
//                    only D(h) and G2 depend on alpha, h the lobe's half vector); df/deta by forward-mode
//                    dual numbers through eval's formulas (eta reaches the refraction lobe's half vector,
//                    D(h), the Fresnel term and the Jacobian)
//   conductor (delta), plastic's coating (delta): df/dR = F / cos
//   roughplastic's coating: df/drho_s = F(wi.h) D G2 / (4 cos_i cos_o)
//   plastic, roughplastic base: df/drho = T_i T_o / (pi eta^2) d(rho')/drho, rho' = rho / (1 - Fdr)
//                    (or rho / (1 - rho Fdr): derivative 1 / (1 - rho Fdr)^2)
#pragma once

#include <cmath>

#include "bsdfs/material.hpp"
#include "diff/parameters.hpp"

namespace pathlab {

namespace bsdf_derivative_detail {

inline Rgb channel(int c, float v) {
    Rgb r(0.0f);
    (&r.x)[c] = v;
    return r;
}

// dLambda/dalpha of an isotropic distribution.
inline float dlambda_dalpha(const MicrofacetDistribution& d, const Vec3f& w) {
    const float z2 = w.z * w.z;
    if (z2 == 0) return 0.0f;
    const float alpha = d.alpha_u;
    const float a2 = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;
    if (a2 == 0) return 0.0f;
    if (d.type == MicrofacetType::GGX) return a2 / (2 * alpha * std::sqrt(1 + a2));
    const double c = 1.0 / std::sqrt(double(a2));
    return float(std::exp(-c * c) / (2 * std::sqrt(M_PI) * c * alpha));
}

// dD/dalpha of an isotropic distribution at the normal h.
inline float dD_dalpha(const MicrofacetDistribution& d, const Vec3f& h) {
    if (h.z <= 0) return 0.0f;
    const float alpha = d.alpha_u, s = h.x * h.x + h.y * h.y, z2 = h.z * h.z;
    const float D = d.D(h);
    if (d.type == MicrofacetType::GGX) {
        const float t = s / (alpha * alpha) + z2;
        return D * (-2 / alpha + 4 * s / (alpha * alpha * alpha * t));
    }
    return D * (2 * s / (alpha * alpha * alpha * z2) - 2 / alpha);
}

// A value and its derivative with respect to one parameter (forward mode): for a rough
// dielectric's eta, which reaches its refraction lobe through the half vector.
struct Dual {
    float v = 0, d = 0;
};
inline Dual operator+(Dual a, Dual b) { return {a.v + b.v, a.d + b.d}; }
inline Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.d - b.d}; }
inline Dual operator-(Dual a) { return {-a.v, -a.d}; }
inline Dual operator*(Dual a, Dual b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
inline Dual operator/(Dual a, Dual b) { return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)}; }
inline Dual constant(float v) { return {v, 0}; }
inline Dual sqrt(Dual a) {
    const float s = std::sqrt(a.v);
    return {s, s > 0 ? a.d / (2 * s) : 0.0f};
}
inline Dual exp(Dual a) {
    const float e = std::exp(a.v);
    return {e, e * a.d};
}

// fresnel_dielectric (fresnel.hpp) with its derivative.
inline Dual fresnel_dielectric(Dual cos_i, Dual eta) {
    const Dual sin2_t = (constant(1) - cos_i * cos_i) / (eta * eta);
    if (sin2_t.v >= 1) return constant(1);
    const Dual ct = sqrt(constant(1) - sin2_t);
    const Dual rs = (cos_i - eta * ct) / (cos_i + eta * ct), rp = (eta * cos_i - ct) / (eta * cos_i + ct);
    return constant(0.5f) * (rs * rs + rp * rp);
}

// MicrofacetDistribution::D (isotropic) at a normal h with its derivative.
inline Dual distribution_D(const MicrofacetDistribution& d, Dual hx, Dual hy, Dual hz) {
    if (hz.v <= 0) return constant(0);
    const float a = d.alpha_u;
    const Dual s = (hx * hx + hy * hy) / constant(a * a), z2 = hz * hz;
    if (d.type == MicrofacetType::GGX) {
        const Dual t = s + z2;
        return constant(1 / (kPi * a * a)) / (t * t);
    }
    return exp(-(s / z2)) / (constant(kPi * a * a) * z2 * z2);
}

// The rough dielectric's f(wi, wo) (roughdielectric.hpp's eval) with its derivative with respect
// to eta = int_ior / ext_ior.
inline Dual roughdielectric_f_eta(const RoughDielectricMaterial& r, Vec3f wi, Vec3f wo) {
    const bool outside = wi.z > 0;
    if (!outside) wi.z = -wi.z, wo.z = -wo.z;
    // int_ior = eta ext_ior: d(int_ior)/d(eta) = ext_ior.
    const Dual n_int{r.int_ior, r.ext_ior}, n_ext = constant(r.ext_ior);
    const Dual eta_i = outside ? n_ext : n_int, eta_o = outside ? n_int : n_ext, eta = eta_o / eta_i;
    const MicrofacetDistribution& d = r.distribution;
    if (wo.z > 0) {  // reflection: only F depends on eta
        const Vec3f h = normalize(wi + wo);
        const float c = dot(wi, h), D = d.D(h);
        if (!(c > 0) || !(D > 0)) return {};
        return fresnel_dielectric(constant(c), eta) * constant(D * d.G2(wi, wo) / (4 * wi.z * wo.z));
    }
    Dual hx = eta_i * constant(wi.x) + eta_o * constant(wo.x), hy = eta_i * constant(wi.y) + eta_o * constant(wo.y),
         hz = eta_i * constant(wi.z) + eta_o * constant(wo.z);
    const Dual len = sqrt(hx * hx + hy * hy + hz * hz);
    if (!(len.v > 0)) return {};
    hx = hx / len, hy = hy / len, hz = hz / len;
    if (hz.v < 0) hx = -hx, hy = -hy, hz = -hz;
    const Dual ci = constant(wi.x) * hx + constant(wi.y) * hy + constant(wi.z) * hz,
               co = constant(wo.x) * hx + constant(wo.y) * hy + constant(wo.z) * hz;
    if (!(ci.v > 0) || !(co.v < 0)) return {};
    const Dual D = distribution_D(d, hx, hy, hz);
    if (!(D.v > 0)) return {};
    const Dual F = eta.v >= 1 ? fresnel_dielectric(ci, eta) : fresnel_dielectric(-co, constant(1) / eta);
    const Dual den = eta_i * ci + eta_o * co;
    if (!(den.v * den.v > 0)) return {};
    return (constant(1) - F) * D * constant(d.G2(wi, wo)) * ci * (-co) * eta_i * eta_i /
           (constant(wi.z * -wo.z) * den * den);
}

// d(rho')/drho of a coated base, per channel (rho' = rho / (1 - Fdr) or rho / (1 - rho Fdr)).
inline Rgb coated_base_derivative(const CoatedDiffuse& c, float fdr) {
    if (!c.nonlinear) return Rgb(1 / (1 - fdr));
    const Rgb d = Rgb(1.0f) - c.diffuse_reflectance * fdr;
    return Rgb(1.0f) / (d * d);
}

// The coating's Fdr, recovered from the precomputed base rho' / (pi eta^2) of a channel with
// rho > 0 (plastic's and roughplastic's constructors compute it by quadrature, too slow per
// vertex); recomputed only for a black base (`compute`).
template <typename Compute>
float coating_fdr(const CoatedDiffuse& c, Compute&& compute) {
    for (int ch = 0; ch < 3; ++ch) {
        const float rho = (&c.diffuse_reflectance.x)[ch], base = (&c.base.x)[ch] * kPi * c.eta * c.eta;  // rho'
        if (rho > 0 && base > 0) return c.nonlinear ? (1 - rho / base) / rho : 1 - rho / base;
    }
    return compute();
}

}  // namespace bsdf_derivative_detail

// Calls add(offset, df/dtheta) for every bound scalar parameter of `m` whose derivative at
// (wi, wo) may be non-zero.
template <typename Add>
void bsdf_jacobian(const Material& m, const MaterialBinding& b, const Vec3f& wi, const Vec3f& wo, bool delta, Add&& add) {
    using namespace bsdf_derivative_detail;
    if (const auto* r = std::get_if<RoughDielectricMaterial>(&m.model)) {
        // Reflection and refraction alike: f = D(h) G2(wi, wo) times factors free of alpha (the
        // Fresnel term at h, the refraction's Jacobian), h the half vector of the lobe, so
        // df/dalpha = f (D'/D + G2'/G2), in the frame where wi is above (as eval: D and Lambda
        // are even in z).
        if (delta || wi.z == 0 || wo.z == 0) return;
        if (b.eta >= 0) add(b.eta, Rgb(roughdielectric_f_eta(*r, wi, wo).d));
        if (b.alpha < 0) return;
        const Rgb f = r->eval(wi, wo);
        if (is_black(f)) return;
        const bool outside = wi.z > 0;
        const Vec3f i(wi.x, wi.y, std::abs(wi.z)), o(wo.x, wo.y, outside ? wo.z : -wo.z);
        const float eta_i = outside ? r->ext_ior : r->int_ior, eta_o = outside ? r->int_ior : r->ext_ior;
        Vec3f h = normalize(o.z > 0 ? i + o : i * eta_i + o * eta_o);
        if (h.z < 0) h = -h;
        const MicrofacetDistribution& d = r->distribution;
        const float D = d.D(h);
        if (!(D > 0)) return;
        const float dlog_G = -(d.G1(i) * dlambda_dalpha(d, i) + d.G1(o) * dlambda_dalpha(d, o));
        add(b.alpha, f * (dD_dalpha(d, h) / D + dlog_G));
        return;
    }
    if (wi.z <= 0 || wo.z <= 0) return;
    if (const auto* p = std::get_if<PhongMaterial>(&m.model)) {
        if (delta) return;
        if (b.diffuse >= 0)
            for (int c = 0; c < 3; ++c) add(b.diffuse + c, channel(c, kInvPi));
        if (b.specular < 0 && b.exponent < 0) return;
        const float cos_alpha = dot(PhongMaterial::mirror(wi), wo);
        if (!(cos_alpha > 0)) return;
        const float n = p->exponent, lobe = std::pow(cos_alpha, n) * (1 / (2 * kPi));
        if (b.specular >= 0)
            for (int c = 0; c < 3; ++c) add(b.specular + c, channel(c, (n + 2) * lobe));
        if (b.exponent >= 0) add(b.exponent, p->specular * (lobe * (1 + (n + 2) * std::log(cos_alpha))));
        return;
    }
    if (const auto* k = std::get_if<ConductorMaterial>(&m.model)) {
        if (!delta || b.specular < 0) return;
        const Rgb F = fresnel_conductor(wi.z, k->eta, k->k) / wo.z;
        for (int c = 0; c < 3; ++c) add(b.specular + c, channel(c, (&F.x)[c]));
        return;
    }
    if (const auto* r = std::get_if<RoughConductorMaterial>(&m.model)) {
        if (delta) return;
        const Vec3f sum = wi + wo;
        const float len = length(sum);
        if (!(len > 0)) return;
        const Vec3f h = sum / len;
        const float cos_ih = dot(wi, h), D = r->distribution.D(h);
        if (!(D > 0) || !(cos_ih > 0)) return;
        const Rgb F = fresnel_conductor(cos_ih, r->eta, r->k) * (1 / (4 * wi.z * wo.z));
        const float G = r->distribution.G2(wi, wo);
        if (b.specular >= 0) {
            const Rgb base = F * (D * G);
            for (int c = 0; c < 3; ++c) add(b.specular + c, channel(c, (&base.x)[c]));
        }
        if (b.alpha >= 0) {
            const float dG = -G * (r->distribution.G1(wi) * dlambda_dalpha(r->distribution, wi) +
                                   r->distribution.G1(wo) * dlambda_dalpha(r->distribution, wo));
            add(b.alpha, r->specular_reflectance * F * (dD_dalpha(r->distribution, h) * G + D * dG));
        }
        return;
    }
    if (const auto* p = std::get_if<PlasticMaterial>(&m.model)) {
        const CoatedDiffuse& c = p->coat;
        const float Fi = c.fresnel(wi.z);
        if (delta) {
            if (b.specular >= 0)
                for (int ch = 0; ch < 3; ++ch) add(b.specular + ch, channel(ch, Fi / wo.z));
            return;
        }
        if (b.diffuse < 0) return;
        const Rgb d = coated_base_derivative(c, coating_fdr(c, [&] { return fresnel_diffuse_reflectance(1 / c.eta); })) *
                      ((1 - Fi) * (1 - c.fresnel(wo.z)) * kInvPi / (c.eta * c.eta));
        for (int ch = 0; ch < 3; ++ch) add(b.diffuse + ch, channel(ch, (&d.x)[ch]));
        return;
    }
    if (const auto* r = std::get_if<RoughPlasticMaterial>(&m.model)) {
        if (delta) return;
        if (b.diffuse >= 0) {
            const Rgb d = coated_base_derivative(r->coat, coating_fdr(r->coat, [&] { return r->coat.fdr; })) *
                          (r->T(wi.z) * r->T(wo.z) * kInvPi / (r->coat.eta * r->coat.eta));
            for (int ch = 0; ch < 3; ++ch) add(b.diffuse + ch, channel(ch, (&d.x)[ch]));
        }
        if (b.specular >= 0) {  // the coating's lobe, linear in its reflectance
            const Vec3f h = normalize(wi + wo);
            const float c = dot(wi, h), D = r->distribution.D(h);
            if (!(c > 0) || !(D > 0)) return;
            const float s = r->coat.fresnel(c) * D * r->distribution.G2(wi, wo) / (4 * wi.z * wo.z);
            for (int ch = 0; ch < 3; ++ch) add(b.specular + ch, channel(ch, s));
        }
    }
}

}  // namespace pathlab
