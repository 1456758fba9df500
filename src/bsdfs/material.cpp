#include "bsdfs/material.hpp"

namespace pathlab {

// The composite models (blendbsdf, mask) out of line: they call Material back, and inlined
// into the dispatch they would make every caller of it larger (pt-mis's hot loop).
Rgb BlendMaterial::eval(const Vec3f& wi, const Vec3f& wo) const {
    return first->eval(wi, wo) * (1 - weight) + second->eval(wi, wo) * weight;
}
float BlendMaterial::pdf(const Vec3f& wi, const Vec3f& wo) const {
    return (1 - weight) * first->pdf(wi, wo) + weight * second->pdf(wi, wo);
}
std::optional<BsdfSample> BlendMaterial::sample(const Vec3f& wi, Vec2f u) const {
    const bool pick_second = u.x < weight;
    const float p = pick_second ? weight : 1 - weight;
    u.x = pick_second ? u.x / weight : (u.x - weight) / (1 - weight);
    u.x = std::min(u.x, 0.99999994f);
    std::optional<BsdfSample> s = (pick_second ? second : first)->sample(wi, u);
    if (!s) return s;
    if (s->delta) {
        s->f *= p;
        s->pdfW *= p;
    } else {
        s->f = eval(wi, s->wo);
        s->pdfW = pdf(wi, s->wo);
        if (!(s->pdfW > 0)) return std::nullopt;
    }
    return s;
}

Rgb MaskMaterial::eval(const Vec3f& wi, const Vec3f& wo) const { return inner->eval(wi, wo) * opacity; }
float MaskMaterial::pdf(const Vec3f& wi, const Vec3f& wo) const { return opacity * inner->pdf(wi, wo); }
std::optional<BsdfSample> MaskMaterial::sample(const Vec3f& wi, Vec2f u) const {
    if (u.x >= opacity) {
        const float c = std::abs(wi.z);
        if (!(c > 0)) return std::nullopt;
        return BsdfSample{-wi, Rgb((1 - opacity) / c), 1 - opacity, true, kLobeSpecular | kLobeTransmission};
    }
    u.x = std::min(u.x / opacity, 0.99999994f);
    std::optional<BsdfSample> s = inner->sample(wi, u);
    if (!s) return s;
    s->f *= opacity;
    s->pdfW *= opacity;
    return s;
}


std::optional<BsdfSample> Material::sample_adjusted(const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u) const {
    std::optional<BsdfSample> s = sample(wi, u);
    if (!s) return s;
    if (ctx.mode == TransportMode::Importance) {
        const float k = importance_factor(ctx, wi, s->wo);
        if (!(k > 0)) return std::nullopt;
        s->f *= k;
    }
    if (ctx.reverse_pdf) s->pdf_rev = s->delta ? s->pdfW : pdf(s->wo, wi);
    return s;
}

float Material::importance_factor(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const {
    const Vec3f ng = ctx.frame.to_local(ctx.ng);
    const float wi_ng = dot(wi, ng), wo_ng = dot(wo, ng);
    if (wi_ng * wi.z <= 0 || wo_ng * wo.z <= 0) return 0.0f;
    float k = std::abs(wi.z * wo_ng) / std::abs(wi_ng * wo.z);
    if (wi.z * wo.z < 0) {
        float int_ior = 1, ext_ior = 1;
        if (const auto* d = std::get_if<DielectricMaterial>(&model)) int_ior = d->int_ior, ext_ior = d->ext_ior;
        if (const auto* d = std::get_if<RoughDielectricMaterial>(&model)) int_ior = d->int_ior, ext_ior = d->ext_ior;
        const float eta_wi = wi.z > 0 ? ext_ior : int_ior, eta_wo = wo.z > 0 ? ext_ior : int_ior;
        k *= (eta_wo * eta_wo) / (eta_wi * eta_wi);
    }
    return k;
}

}  // namespace pathlab
