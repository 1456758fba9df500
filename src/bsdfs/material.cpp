#include "bsdfs/material.hpp"

namespace pathlab {
namespace {

// Radiance-mode values of a model (std::visit: the hot loop's inlined dispatch is visit_model).
Rgb eval_of(const MaterialModel& m, const Vec3f& wi, const Vec3f& wo) {
    return std::visit([&](const auto& x) { return x.eval(wi, wo); }, m);
}
float pdf_of(const MaterialModel& m, const Vec3f& wi, const Vec3f& wo) {
    return std::visit([&](const auto& x) { return x.pdf(wi, wo); }, m);
}
Rgb eval_and_pdf_of(const MaterialModel& m, const Vec3f& wi, const Vec3f& wo, float& pdf) {
    return std::visit(
        [&](const auto& x) {
            if constexpr (requires { x.eval_and_pdf(wi, wo, pdf); }) {
                return x.eval_and_pdf(wi, wo, pdf);
            } else {
                pdf = x.pdf(wi, wo);
                return x.eval(wi, wo);
            }
        },
        m);
}

// Both directions on the same side of the geometric surface as of the shading one.
bool sides_agree(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) {
    const Vec3f ng = ctx.frame.to_local(ctx.ng);
    return dot(wi, ng) * wi.z > 0 && dot(wo, ng) * wo.z > 0;
}

}  // namespace

void Material::prepare() {
    varies = textures != nullptr;
    // Anisotropic microfacets (alpha_u != alpha_v, or either given by a texture) act along dp/du.
    const MicrofacetDistribution* d = nullptr;
    if (const auto* r = std::get_if<RoughConductorMaterial>(&model)) d = &r->distribution;
    if (const auto* r = std::get_if<RoughDielectricMaterial>(&model)) d = &r->distribution;
    bool anisotropic = d && d->is_anisotropic();
    if (d && textures)
        for (const TextureBinding& b : textures->bindings)
            anisotropic = anisotropic || b.slot == MicrofacetDistribution::kSlotAlphaU || b.slot == MicrofacetDistribution::kSlotAlphaV;
    const auto disney = [&](float a, int slot) {
        anisotropic = a > 0;
        if (textures)
            for (const TextureBinding& b : textures->bindings) anisotropic = anisotropic || b.slot == slot;
    };
    if (const auto* p = std::get_if<PrincipledMaterial>(&model)) disney(p->anisotropic, PrincipledMaterial::kSlotAnisotropic);
    if (const auto* p = std::get_if<PrincipledThinMaterial>(&model)) disney(p->anisotropic, PrincipledThinMaterial::kSlotAnisotropic);
    tangent_frame = anisotropic || perturbed();
    // blendbsdf and mask vary where their nested materials do, and take their tangent frames.
    const auto nested = [&](const Material& inner) {
        Material c = inner;
        c.prepare();
        varies = varies || c.varies;
        tangent_frame = tangent_frame || c.tangent_frame;
    };
    if (const auto* b = std::get_if<BlendMaterial>(&model)) nested(*b->first), nested(*b->second);
    if (const auto* m = std::get_if<MaskMaterial>(&model)) nested(*m->inner);
    surface_coordinates = varies || tangent_frame;
}

MaterialModel Material::model_at(const SurfaceUv& uv) const {
    MaterialModel m = model;
    std::visit(
        [&](auto& x) {
            if constexpr (requires { x.set_uv(uv); }) x.set_uv(uv);  // blendbsdf, mask: for their nested materials
        },
        m);
    if (!textures || textures->bindings.empty()) return m;
    for (const TextureBinding& b : textures->bindings) {
        const Rgb v = b.scalar ? Rgb(b.texture->eval_1(uv)) : b.texture->eval(uv);
        std::visit(
            [&](auto& x) {
                if constexpr (requires { x.set_texel(b.slot, v); }) x.set_texel(b.slot, v);
            },
            m);
    }
    std::visit(
        [](auto& x) {
            if constexpr (requires { x.texels_changed(); }) x.texels_changed();
        },
        m);
    return m;
}

Frame Material::shading_frame(const Vec3f& n, const Vec3f& ng, bool back, const Vec3f& dpdu, const Vec3f& dpdv, const SurfaceUv& uv) const {
    const Frame f = perturbed() ? perturbed_frame(*textures, n, ng, dpdu, dpdv, uv) : pathlab::tangent_frame(n, dpdu);
    if (!back) return f;
    Frame r;
    r.n = -f.n;
    r.s = f.s;
    r.t = cross(r.n, r.s);
    return r;
}

float Material::context_factor(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const {
    if (ctx.mode == TransportMode::Importance) return importance_factor(ctx, wi, wo);
    return perturbed() ? perturbation_factor(ctx, wi, wo) : 1.0f;
}

float Material::perturbation_factor(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const {
    if (!mitsuba_bump_rules() || ctx.ns == Vec3f(0.0f)) return sides_agree(ctx, wi, wo) ? 1.0f : 0.0f;
    // Mitsuba's: wo on one side of the shading normal before and after the map, times the shadowing.
    const Vec3f n = ctx.frame.to_local(ctx.ns);
    const float cos_o = dot(wo, n);
    if (!(cos_o * wo.z > 0)) return 0.0f;
    return textures->shadowing_function ? bump_shadowing(n.z, cos_o) : 1.0f;
}

Rgb Material::eval_varying(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const {
    return eval_of(model_at(ctx.uv), wi, wo) * context_factor(ctx, wi, wo);
}

float Material::pdf_varying(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo) const { return pdf_of(model_at(ctx.uv), wi, wo); }

Rgb Material::eval_and_pdf_varying(const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, float& pdf) const {
    return eval_and_pdf_of(model_at(ctx.uv), wi, wo, pdf) * context_factor(ctx, wi, wo);
}

// The composite models (blendbsdf, mask) out of line: they call Material back, and inlined
// into the dispatch they would make every caller of it larger (pt-mis's hot loop). A nested
// material that varies is evaluated at the composite's uv (its radiance-mode model there: the
// transport mode is applied once, by the composite's Material).
namespace {
Rgb eval_at(const Material& m, const SurfaceUv& uv, const Vec3f& wi, const Vec3f& wo) {
    return m.varies ? eval_of(m.model_at(uv), wi, wo) : m.eval(wi, wo);
}
float pdf_at(const Material& m, const SurfaceUv& uv, const Vec3f& wi, const Vec3f& wo) {
    return m.varies ? pdf_of(m.model_at(uv), wi, wo) : m.pdf(wi, wo);
}
std::optional<BsdfSample> sample_at(const Material& m, const SurfaceUv& uv, const Vec3f& wi, const Vec2f& u) {
    if (!m.varies) return m.sample(wi, u);
    return std::visit([&](const auto& x) { return x.sample(wi, u); }, m.model_at(uv));
}
}  // namespace

Rgb BlendMaterial::eval(const Vec3f& wi, const Vec3f& wo) const {
    return eval_at(*first, uv, wi, wo) * (1 - weight) + eval_at(*second, uv, wi, wo) * weight;
}
float BlendMaterial::pdf(const Vec3f& wi, const Vec3f& wo) const {
    return (1 - weight) * pdf_at(*first, uv, wi, wo) + weight * pdf_at(*second, uv, wi, wo);
}
std::optional<BsdfSample> BlendMaterial::sample(const Vec3f& wi, Vec2f u) const {
    const bool pick_second = u.x < weight;
    const float p = pick_second ? weight : 1 - weight;
    u.x = pick_second ? u.x / weight : (u.x - weight) / (1 - weight);
    u.x = std::min(u.x, 0.99999994f);
    std::optional<BsdfSample> s = sample_at(pick_second ? *second : *first, uv, wi, u);
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

float Material::null_transmission(const SurfaceUv& uv, float cos_i) const {
    if (!(lobes() & kLobeNull)) return 0.0f;
    const MaterialModel m = varies ? model_at(uv) : model;
    if (const auto* t = std::get_if<ThinDielectricMaterial>(&m)) return 1 - t->reflectance(cos_i);
    if (const auto* k = std::get_if<MaskMaterial>(&m)) return (1 - k->opacity) + k->opacity * k->inner->null_transmission(uv, cos_i);
    if (const auto* b = std::get_if<BlendMaterial>(&m))
        return (1 - b->weight) * b->first->null_transmission(uv, cos_i) + b->weight * b->second->null_transmission(uv, cos_i);
    return 0.0f;
}

Rgb MaskMaterial::eval(const Vec3f& wi, const Vec3f& wo) const { return eval_at(*inner, uv, wi, wo) * opacity; }
float MaskMaterial::pdf(const Vec3f& wi, const Vec3f& wo) const { return opacity * pdf_at(*inner, uv, wi, wo); }
std::optional<BsdfSample> MaskMaterial::sample(const Vec3f& wi, Vec2f u) const {
    if (u.x >= opacity) {
        const float c = std::abs(wi.z);
        if (!(c > 0)) return std::nullopt;
        return BsdfSample{-wi, Rgb((1 - opacity) / c), 1 - opacity, true, kLobeSpecular | kLobeTransmission | kLobeNull};
    }
    u.x = std::min(u.x / opacity, 0.99999994f);
    std::optional<BsdfSample> s = sample_at(*inner, uv, wi, u);
    if (!s) return s;
    s->f *= opacity;
    s->pdfW *= opacity;
    return s;
}


std::optional<BsdfSample> Material::sample_adjusted(const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u) const {
    const auto adjust = [&](const MaterialModel& m) -> std::optional<BsdfSample> {
        std::optional<BsdfSample> s = visit_model(m, [&](const auto& x) { return x.sample(wi, u); });
        if (!s) return s;
        if (ctx.mode == TransportMode::Importance) {
            const float k = importance_factor(ctx, wi, s->wo);
            if (!(k > 0)) return std::nullopt;
            s->f *= k;
        } else if (perturbed()) {
            const float k = perturbation_factor(ctx, wi, s->wo);
            if (!(k > 0)) return std::nullopt;
            s->f *= k;
        }
        if (ctx.reverse_pdf) s->pdf_rev = s->delta ? s->pdfW : pdf_of(m, s->wo, wi);
        return s;
    };
    if (!varies) return adjust(model);
    return adjust(model_at(ctx.uv));
}

std::vector<Material::AttributeUse> Material::mesh_attributes_read() const {
    std::vector<AttributeUse> out;
    const auto add = [&](const std::shared_ptr<const Texture>& t, bool scalar) {
        if (const auto* a = t ? std::get_if<MeshAttributeTexture>(&t->model()) : nullptr) out.push_back({a->name, scalar});
    };
    if (textures) {
        for (const TextureBinding& b : textures->bindings) add(b.texture, b.scalar);
        add(textures->perturbation_texture, textures->perturbation == FramePerturbation::BumpMap);
    }
    const auto nested = [&](const Material& inner) {
        for (AttributeUse& u : inner.mesh_attributes_read()) out.push_back(std::move(u));
    };
    if (const auto* b = std::get_if<BlendMaterial>(&model)) nested(*b->first), nested(*b->second);
    if (const auto* m = std::get_if<MaskMaterial>(&model)) nested(*m->inner);
    return out;
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
        if (const auto* d = std::get_if<PrincipledMaterial>(&model)) int_ior = d->eta;
        const float eta_wi = wi.z > 0 ? ext_ior : int_ior, eta_wo = wo.z > 0 ? ext_ior : int_ior;
        k *= (eta_wo * eta_wo) / (eta_wi * eta_wi);
    }
    return k;
}

}  // namespace pathlab
