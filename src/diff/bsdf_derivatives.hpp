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
//   microfacet roughness (roughconductor, roughdielectric, roughplastic's coating): a lobe is D(h) G2(wi, wo)
//                    times factors free of alpha, so d lobe/dalpha_u = lobe (dD/dalpha_u / D + dG2/dalpha_u / G2)
//                    (and alike for alpha_v; an isotropic alpha moves both: the sum), G2 = G1(wi) G1(wo),
//                    dG2/G2 = -(G1(wi) Lambda'(wi) + G1(wo) Lambda'(wo)); the formulas of D' and Lambda'
//                    for GGX and Beckmann at dD_dalpha and dlambda_dalpha
//   roughconductor:  df/dR = F D G2 / (4 cos_i cos_o)
//   roughdielectric: reflection and refraction alike (wi on either side; only D(h) and G2 depend on
//                    alpha, h the lobe's half vector); df/deta by forward-mode
//                    dual numbers through eval's formulas (eta reaches the refraction lobe's half vector,
//                    D(h), the Fresnel term and the Jacobian)
//   conductor (delta), plastic's coating (delta): df/dR = F / cos
//   roughplastic's coating: df/drho_s = F(wi.h) D G2 / (4 cos_i cos_o); its alpha also moves the base
//                    rho' T(cos_i) T(cos_o) / (pi eta^2) through the tables T and Fdr (RoughCoatingDerivative)
//   plastic, roughplastic base: df/drho = T_i T_o / (pi eta^2) d(rho')/drho, rho' = rho / (1 - Fdr)
//                    (or rho / (1 - rho Fdr): derivative 1 / (1 - rho Fdr)^2)
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "bsdfs/material.hpp"
#include "diff/parameters.hpp"

namespace pathlab {

namespace bsdf_derivative_detail {

inline Rgb channel(int c, float v) {
    Rgb r(0.0f);
    (&r.x)[c] = v;
    return r;
}

// Derivatives with respect to the two roughnesses, alpha_u (along x) and alpha_v (along y); an
// isotropic distribution's alpha moves both, so its derivative is their sum.
struct AlphaPair {
    float u = 0, v = 0;
    float sum() const { return u + v; }
};

// dLambda/dalpha_u, dLambda/dalpha_v: Lambda depends on them through a2 = (au^2 wx^2 + av^2 wy^2) / wz^2,
// da2/dau = 2 au wx^2 / wz^2; GGX: dLambda/da2 = 1 / (4 sqrt(1 + a2)); Beckmann (c = 1/sqrt(a2)):
// dLambda/da2 = c exp(-c^2) / (4 sqrt(pi)).
inline AlphaPair dlambda_dalpha(const MicrofacetDistribution& d, const Vec3f& w) {
    const float z2 = w.z * w.z;
    if (z2 == 0) return {};
    const float a2 = (d.alpha_u * d.alpha_u * w.x * w.x + d.alpha_v * d.alpha_v * w.y * w.y) / z2;
    if (a2 == 0) return {};
    float dl_da2;
    if (d.type == MicrofacetType::GGX) {
        dl_da2 = 1 / (4 * std::sqrt(1 + a2));
    } else {
        const double c = 1.0 / std::sqrt(double(a2));
        dl_da2 = float(c * std::exp(-c * c) / (4 * std::sqrt(M_PI)));
    }
    return {dl_da2 * 2 * d.alpha_u * w.x * w.x / z2, dl_da2 * 2 * d.alpha_v * w.y * w.y / z2};
}

// dD/dalpha_u, dD/dalpha_v at the normal h: GGX, D = 1 / (pi au av t^2), t = hx^2/au^2 + hy^2/av^2 + hz^2,
// dD/dau = D (-1/au + 4 hx^2 / (au^3 t)); Beckmann, D = exp(-(hx^2/au^2 + hy^2/av^2) / hz^2) / (pi au av hz^4),
// dD/dau = D (2 hx^2 / (au^3 hz^2) - 1/au); alike for av with hy.
inline AlphaPair dD_dalpha(const MicrofacetDistribution& d, const Vec3f& h) {
    if (h.z <= 0) return {};
    const float au = d.alpha_u, av = d.alpha_v, x2 = h.x * h.x, y2 = h.y * h.y, z2 = h.z * h.z;
    const float D = d.D(h);
    if (d.type == MicrofacetType::GGX) {
        const float t = x2 / (au * au) + y2 / (av * av) + z2;
        return {D * (-1 / au + 4 * x2 / (au * au * au * t)), D * (-1 / av + 4 * y2 / (av * av * av * t))};
    }
    return {D * (2 * x2 / (au * au * au * z2) - 1 / au), D * (2 * y2 / (av * av * av * z2) - 1 / av)};
}

// d log(D(h) G2(wi, wo)) / d alpha_u, alpha_v, where D(h) > 0: a microfacet lobe is D G2 times
// factors free of the roughness (Fresnel, the Jacobian), so its derivative is the lobe times this.
// G2 = G1(wi) G1(wo) (separable), G1 = 1 / (1 + Lambda): d log G2 = -(G1(wi) Lambda'(wi) + G1(wo) Lambda'(wo)).
inline AlphaPair dlog_DG2(const MicrofacetDistribution& d, const Vec3f& h, const Vec3f& wi, const Vec3f& wo) {
    const float D = d.D(h), gi = d.G1(wi), go = d.G1(wo);
    const AlphaPair dD = dD_dalpha(d, h), li = dlambda_dalpha(d, wi), lo = dlambda_dalpha(d, wo);
    return {dD.u / D - (gi * li.u + go * lo.u), dD.v / D - (gi * li.v + go * lo.v)};
}

// Adds a lobe's roughness derivatives: df/dalpha = lobe (dlog.u + dlog.v) for an isotropic
// alpha, lobe dlog.u and lobe dlog.v for alpha_u and alpha_v.
template <typename Add>
void add_roughness(const MaterialBinding& b, const Rgb& lobe, AlphaPair dlog, Add&& add) {
    if (b.alpha >= 0) add(b.alpha, lobe * dlog.sum());
    if (b.alpha_u >= 0) add(b.alpha_u, lobe * dlog.u);
    if (b.alpha_v >= 0) add(b.alpha_v, lobe * dlog.v);
}

// A value and its derivative with respect to one parameter (forward mode): for a rough
// dielectric's eta, which reaches its refraction lobe through the half vector. In double: the
// refraction lobe's formulas cancel (the half vector's normalisation, 1 - F).
struct Dual {
    double v = 0, d = 0;
};
inline Dual operator+(Dual a, Dual b) { return {a.v + b.v, a.d + b.d}; }
inline Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.d - b.d}; }
inline Dual operator-(Dual a) { return {-a.v, -a.d}; }
inline Dual operator*(Dual a, Dual b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
inline Dual operator/(Dual a, Dual b) { return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)}; }
inline Dual constant(double v) { return {v, 0}; }
inline Dual sqrt(Dual a) {
    const double s = std::sqrt(a.v);
    return {s, s > 0 ? a.d / (2 * s) : 0.0};
}
inline Dual exp(Dual a) {
    const double e = std::exp(a.v);
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

// MicrofacetDistribution::D at a normal h with its derivative.
inline Dual distribution_D(const MicrofacetDistribution& d, Dual hx, Dual hy, Dual hz) {
    if (hz.v <= 0) return constant(0);
    const float au = d.alpha_u, av = d.alpha_v;
    const Dual s = hx * hx / constant(au * au) + hy * hy / constant(av * av), z2 = hz * hz;
    if (d.type == MicrofacetType::GGX) {
        const Dual t = s + z2;
        return constant(1 / (kPi * au * av)) / (t * t);
    }
    return exp(-(s / z2)) / (constant(kPi * au * av) * z2 * z2);
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

// d/dalpha of roughplastic's precomputed coating terms, its transmittance table T(mu) and its
// internal reflectance Fdr: quadratures over the visible normals (roughplastic.hpp), whose
// derivative is taken as central differences of the tables built again at alpha (1 +- 2%). The
// quadratures are smooth in alpha only to the scale of their nodes (a node's visible normal
// crossing the critical angle is a kink): slopes of Fdr over steps of 0.2% to 4% of alpha spread
// by 2% (GGX and Beckmann, alpha 0.3); at 2% they are within 1% of the slope of a 16x finer
// quadrature (-0.3765 against -0.3761 for Beckmann, -0.7020 against -0.7086 for GGX).
// Computed once per material and gradient (two table builds).
struct RoughCoatingDerivative {
    std::array<float, RoughPlasticMaterial::kTableSize> dT{};
    float dfdr = 0;

    explicit RoughCoatingDerivative(const RoughPlasticMaterial& r) {
        const MicrofacetDistribution& d = r.distribution;
        const float h = 0.02f * d.alpha_u;
        const RoughPlasticMaterial up(MicrofacetDistribution(d.type, d.alpha_u + h, d.alpha_u + h), r.coat),
            down(MicrofacetDistribution(d.type, d.alpha_u - h, d.alpha_u - h), r.coat);
        for (size_t k = 0; k < dT.size(); ++k) dT[k] = (up.transmittance[k] - down.transmittance[k]) / (2 * h);
        dfdr = (up.coat.fdr - down.coat.fdr) / (2 * h);
    }
    // dT/dalpha at mu, interpolated as RoughPlasticMaterial::T interpolates T.
    float dT_at(float mu) const { return RoughPlasticMaterial::lookup(dT, mu); }
};

// Calls add(offset, df/dtheta) for every bound scalar parameter of `m` whose derivative at
// (wi, wo) may be non-zero. `coating`: a roughplastic's RoughCoatingDerivative where its alpha is
// bound (required there), else nullptr.
template <typename Add>
void bsdf_jacobian(const Material& m, const MaterialBinding& b, const RoughCoatingDerivative* coating, const Vec3f& wi, const Vec3f& wo,
                   bool delta, Add&& add) {
    using namespace bsdf_derivative_detail;
    if (const auto* r = std::get_if<RoughDielectricMaterial>(&m.model)) {
        // Reflection and refraction alike: f = D(h) G2(wi, wo) times factors free of alpha (the
        // Fresnel term at h, the refraction's Jacobian), h the half vector of the lobe, so
        // df/dalpha = f (D'/D + G2'/G2), in the frame where wi is above (as eval: D and Lambda
        // are even in z).
        if (delta || wi.z == 0 || wo.z == 0) return;
        if (b.eta >= 0) add(b.eta, Rgb(float(roughdielectric_f_eta(*r, wi, wo).d)));
        if (b.alpha < 0 && b.alpha_u < 0 && b.alpha_v < 0) return;
        const Rgb f = r->eval(wi, wo);
        if (is_black(f)) return;
        const bool outside = wi.z > 0;
        const Vec3f i(wi.x, wi.y, std::abs(wi.z)), o(wo.x, wo.y, outside ? wo.z : -wo.z);
        const float eta_i = outside ? r->ext_ior : r->int_ior, eta_o = outside ? r->int_ior : r->ext_ior;
        Vec3f h = normalize(o.z > 0 ? i + o : i * eta_i + o * eta_o);
        if (h.z < 0) h = -h;
        if (!(r->distribution.D(h) > 0)) return;
        add_roughness(b, f, dlog_DG2(r->distribution, h, i, o), add);
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
        add_roughness(b, r->specular_reflectance * F * (D * G), dlog_DG2(r->distribution, h, wi, wo), add);
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
        const Vec3f h = normalize(wi + wo);
        const float c = dot(wi, h), D = r->distribution.D(h);
        const float s = c > 0 && D > 0 ? r->coat.fresnel(c) * D * r->distribution.G2(wi, wo) / (4 * wi.z * wo.z) : 0.0f;
        if (b.specular >= 0 && s > 0)  // the coating's lobe, linear in its reflectance
            for (int ch = 0; ch < 3; ++ch) add(b.specular + ch, channel(ch, s));
        if (b.alpha >= 0) {
            if (!coating) throw std::logic_error("bsdf_jacobian: a roughplastic's alpha needs its RoughCoatingDerivative");
            // The coating's lobe (D G2), and the base through T(cos_i) T(cos_o) and Fdr:
            // base = rho / (1 - Fdr) / (pi eta^2), d base/dFdr = base / (1 - Fdr)
            // (nonlinear: rho / (1 - rho Fdr) / (pi eta^2), d base/dFdr = base rho / (1 - rho Fdr)).
            Rgb df(0.0f);
            if (s > 0) df = r->coat.specular_reflectance * (s * dlog_DG2(r->distribution, h, wi, wo).sum());
            const CoatedDiffuse& k = r->coat;
            const Rgb dbase_dfdr = k.nonlinear ? k.base * k.diffuse_reflectance / (Rgb(1.0f) - k.diffuse_reflectance * k.fdr)
                                               : k.base / (1 - k.fdr);
            const float Ti = r->T(wi.z), To = r->T(wo.z);
            df += dbase_dfdr * (coating->dfdr * Ti * To) + k.base * (coating->dT_at(wi.z) * To + Ti * coating->dT_at(wo.z));
            add(b.alpha, df);
        }
    }
}

}  // namespace pathlab
