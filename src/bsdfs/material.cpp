#include "bsdfs/material.hpp"

namespace pathlab {

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
