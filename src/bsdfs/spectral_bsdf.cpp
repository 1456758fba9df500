#include "bsdfs/spectral_bsdf.hpp"

#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "spectral/metals.hpp"
#include "spectral/rgb_spectra.hpp"

namespace pathlab {

const char* spectral_material_names() {
    return "diffuse, phong, conductor, roughconductor, dielectric, roughdielectric, thindielectric, plastic, roughplastic, principled, "
           "principledthin, "
           "blendbsdf (at most one of its two with Dirac lobes), mask (of a non-dispersive material)";
}

namespace {

bool is_dispersive(const MaterialModel& m) {
    if (const auto* d = std::get_if<DielectricMaterial>(&m)) return d->dispersion != nullptr;
    if (const auto* d = std::get_if<RoughDielectricMaterial>(&m)) return d->dispersion != nullptr;
    return false;
}

}  // namespace

bool is_dispersive(const Material& m) { return is_dispersive(m.model); }

namespace {

// Whether the material can sample a Dirac delta.
bool has_delta_lobe(const Material& m) { return (m.lobes() & kLobeSpecular) != 0; }

}  // namespace

std::string spectral_unsupported_model(const Material& m) {
    // A nested material is evaluated through its parent, which cannot reduce the wavelengths
    // (a dispersive one) nor tell which of two Dirac lobes was sampled (spectral_sample_value).
    const auto nested = [](const Material& inner, const char* parent) -> std::string {
        if (is_dispersive(inner.model)) return fmt::format("a dispersive dielectric inside {}", parent);
        return spectral_unsupported_model(inner);
    };
    if (const auto* b = std::get_if<BlendMaterial>(&m.model)) {
        if (has_delta_lobe(*b->first) && has_delta_lobe(*b->second)) return "blendbsdf of two materials with Dirac lobes";
        if (auto why = nested(*b->first, "blendbsdf"); !why.empty()) return why;
        return nested(*b->second, "blendbsdf");
    }
    if (const auto* k = std::get_if<MaskMaterial>(&m.model)) return nested(*k->inner, "mask");
    return "";
}

namespace {

// eta(lambda) and k(lambda) of the measured metals at every nm, built on first use.
struct DenseMetal {
    const MeasuredConductor* metal;
    DenseSpectrum eta, k;
};
const DenseMetal& dense_metal(const MeasuredConductor* metal) {
    static const std::vector<DenseMetal> table = [] {
        std::vector<DenseMetal> t;
        for (const char* name : {"Au", "Ag", "Cu", "Al", "Cr", "a-C"}) {
            const MeasuredConductor* m = measured_conductor(name);
            t.push_back({m, DenseSpectrum(m->eta), DenseSpectrum(m->k)});
        }
        return t;
    }();
    for (const DenseMetal& d : table)
        if (d.metal == metal) return d;
    throw std::logic_error("a measured conductor without its table");
}

// A reflectance at the wavelengths: the scene file's spectrum where it gave one, else rgb upsampled.
Spectrum4 reflectance(const Rgb& rgb, const std::shared_ptr<const DenseSpectrum>* given, const SampledWavelengths& wl) {
    if (given && *given) return (*given)->sample(wl);
    return reflectance_spectrum(rgb, wl);
}
const std::shared_ptr<const DenseSpectrum>* diffuse_of(const MaterialSpectra* s) { return s ? &s->diffuse : nullptr; }
const std::shared_ptr<const DenseSpectrum>* specular_of(const MaterialSpectra* s) { return s ? &s->specular : nullptr; }

// A conductor's specular reflectance times its Fresnel reflectance at cos_i, per lane: eta and
// k measured (a named metal) or the RGB ones upsampled.
Spectrum4 conductor_reflectance(const Spectrum4& R, const Rgb& eta, const Rgb& k, const MeasuredConductor* measured, float cos_i,
                                const SampledWavelengths& wl) {
    Spectrum4 e, kk;
    if (measured) {
        const DenseMetal& d = dense_metal(measured);
        e = d.eta.sample(wl), kk = d.k.sample(wl);
    } else {
        e = unbounded_spectrum(eta, wl), kk = unbounded_spectrum(k, wl);
    }
    Spectrum4 F;
    for (int i = 0; i < kSpectrumLanes; ++i) F[i] = fresnel_conductor(cos_i, e[i], kk[i]);
    return R * F;
}

// rho' / (pi eta^2) of a coated diffuse base (plastic.hpp's CoatedDiffuse::base) per lane.
Spectrum4 coat_base(const CoatedDiffuse& coat, const MaterialSpectra* spectra, const SampledWavelengths& wl) {
    const Spectrum4 rho = reflectance(coat.diffuse_reflectance, diffuse_of(spectra), wl);
    const Spectrum4 denom = coat.nonlinear ? Spectrum4(1.0f) - rho * coat.fdr : Spectrum4(1.0f - coat.fdr);
    return rho / denom * (kInvPi / (coat.eta * coat.eta));
}

// The model's value at the wavelengths, without the shading context's factor: the RGB
// formulas of the bsdf headers with each colour parameter replaced by its spectrum (models
// whose value has no colour parameter give their grey RGB value); `spectra`: the reflectances
// the scene file gave as spectra (or null).
Spectrum4 model_value(const MaterialModel& model, const MaterialSpectra* spectra, const Vec3f& wi, const Vec3f& wo,
                      const SampledWavelengths& wl) {
    if (const auto* p = std::get_if<PhongMaterial>(&model)) {
        // rho_d / pi + rho_s (n + 2) cos^n / (2 pi), as phong.hpp.
        Spectrum4 f = reflectance(p->diffuse, diffuse_of(spectra), wl) * kInvPi;
        if (!is_black(p->specular)) {
            const float cos_alpha = dot(PhongMaterial::mirror(wi), wo);
            if (cos_alpha > 0)
                f += reflectance(p->specular, specular_of(spectra), wl) *
                     ((p->exponent + 2) * std::pow(cos_alpha, p->exponent) * (1 / (2 * kPi)));
        }
        return f;
    }
    if (const auto* c = std::get_if<RoughConductorMaterial>(&model)) {
        // R F(cos_ih) D G / (4 cos_i cos_o): the model's value with a white perfect mirror's
        // Fresnel (eta 0, k 1: F = 1) is the scalar part.
        RoughConductorMaterial white = *c;
        white.eta = Rgb(0.0f);
        white.k = Rgb(1.0f);
        white.specular_reflectance = Rgb(1.0f);
        const float g = white.eval(wi, wo).x;
        if (g == 0) return Spectrum4(0.0f);
        const float cos_ih = dot(wi, normalize(wi + wo));
        const Spectrum4 R = reflectance(c->specular_reflectance, specular_of(spectra), wl);
        return conductor_reflectance(R, c->eta, c->k, c->measured, cos_ih, wl) * g;
    }
    if (const auto* p = std::get_if<PlasticMaterial>(&model)) {
        // base (1 - F_i)(1 - F_o), as plastic.hpp.
        if (wi.z <= 0 || wo.z <= 0) return Spectrum4(0.0f);
        return coat_base(p->coat, spectra, wl) * ((1 - p->coat.fresnel(wi.z)) * (1 - p->coat.fresnel(wo.z)));
    }
    if (const auto* p = std::get_if<RoughPlasticMaterial>(&model)) {
        // base T(cos_i) T(cos_o) + specular_reflectance F(wi.h) D G2 / (4 cos_i cos_o), as roughplastic.hpp.
        if (wi.z <= 0 || wo.z <= 0) return Spectrum4(0.0f);
        Spectrum4 f = coat_base(p->coat, spectra, wl) * (p->T(wi.z) * p->T(wo.z));
        const Vec3f h = normalize(wi + wo);
        const float c = dot(wi, h), D = p->distribution.D(h);
        if (c > 0 && D > 0)
            f += reflectance(p->coat.specular_reflectance, specular_of(spectra), wl) *
                 (p->coat.fresnel(c) * D * p->distribution.G2(wi, wo) / (4 * wi.z * wo.z));
        return f;
    }
    if (const auto* p = std::get_if<PrincipledMaterial>(&model)) {
        // a + b c + c_sqrt sqrt(c) with the base colour c at the wavelengths, as principled.hpp.
        float unused;
        const Spectrum4 c = reflectance(p->base_color, nullptr, wl);
        return p->terms(wi, wo, unused).value(c, sqrt(c));
    }
    if (const auto* p = std::get_if<PrincipledThinMaterial>(&model)) {  // a + b c
        float unused;
        const Spectrum4 c = reflectance(p->base_color, nullptr, wl);
        return p->terms(wi, wo, unused).value(c, sqrt(c));
    }
    const auto nested = [&](const Material& m, const SurfaceUv& uv) {
        return model_value(m.varies ? m.model_at(uv) : m.model, m.spectra.get(), wi, wo, wl);
    };
    if (const auto* b = std::get_if<BlendMaterial>(&model))
        return nested(*b->first, b->uv) * (1 - b->weight) + nested(*b->second, b->uv) * b->weight;
    if (const auto* k = std::get_if<MaskMaterial>(&model)) return nested(*k->inner, k->uv) * k->opacity;
    // The rough dielectric is grey (a dispersive one is evaluated at the hero's index by the
    // callers); the smooth conductor and dielectrics have Dirac lobes only, no value for wo.
    if (const auto* d = std::get_if<RoughDielectricMaterial>(&model)) return Spectrum4(d->eval(wi, wo).x);
    return Spectrum4(0.0f);
}

// The colour of the Dirac lobe that produced the delta sample s (wo) of `model`, in RGB and
// at the wavelengths: the sample's RGB value is a multiple of the RGB one (the Fresnel factor,
// 1 / cos, a selection probability, an opacity, the context's factor), and its spectral value
// the same multiple of the spectral one.
struct LobeColour {
    Rgb rgb{1.0f};
    Spectrum4 spectral{1.0f};
};
LobeColour delta_lobe_colour(const MaterialModel& model, const MaterialSpectra* spectra, const Vec3f& wi, const Vec3f& wo,
                             const SampledWavelengths& wl) {
    if (const auto* c = std::get_if<ConductorMaterial>(&model)) {
        const Spectrum4 R = reflectance(c->specular_reflectance, specular_of(spectra), wl);
        return {c->fresnel(wi.z), conductor_reflectance(R, c->eta, c->k, c->measured, wi.z, wl)};
    }
    if (const auto* p = std::get_if<PlasticMaterial>(&model))
        return {p->coat.specular_reflectance, reflectance(p->coat.specular_reflectance, specular_of(spectra), wl)};
    const auto nested = [&](const Material& m, const SurfaceUv& uv) {
        return delta_lobe_colour(m.varies ? m.model_at(uv) : m.model, m.spectra.get(), wi, wo, wl);
    };
    if (const auto* b = std::get_if<BlendMaterial>(&model))  // at most one of the two has Dirac lobes (spectral_unsupported_model)
        return nested(has_delta_lobe(*b->first) ? *b->first : *b->second, b->uv);
    if (const auto* k = std::get_if<MaskMaterial>(&model)) {
        if (wo == -wi) return {};  // straight through: grey
        return nested(*k->inner, k->uv);
    }
    return {};  // the smooth and thin dielectrics: grey
}

const MaterialModel& model_here(const Material& m, const BsdfContext& ctx, MaterialModel& storage) {
    if (!m.varies) return m.model;
    storage = m.model_at(ctx.uv);
    return storage;
}

// A copy of the material whose dispersive interior index is the hero wavelength's.
Material at_hero_index(const Material& m, const SampledWavelengths& wl) {
    Material hero = m;
    std::visit(
        [&](auto& x) {
            if constexpr (requires { x.dispersion; }) x.int_ior = float((*x.dispersion)(wl[0]));
        },
        hero.model);
    return hero;
}

}  // namespace

Spectrum4 spectral_eval(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, const Rgb& f_rgb,
                        const SampledWavelengths& wl) {
    if (is_black(f_rgb)) return Spectrum4(0.0f);
    MaterialModel storage;
    const MaterialModel& model = model_here(m, ctx, storage);
    if (std::holds_alternative<RoughDielectricMaterial>(model)) return Spectrum4(f_rgb.x);  // grey, the context's factor included
    Spectrum4 f = model_value(model, m.spectra.get(), wi, wo, wl);
    if (ctx.mode == TransportMode::Importance) f *= m.importance_factor(ctx, wi, wo);
    return f;
}

Spectrum4 spectral_eval_and_pdf(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, SampledWavelengths& wl,
                                float& pdf) {
    if (is_dispersive(m.model)) [[unlikely]] {
        // The rough dispersive dielectric: its value and density at the hero's index; the path
        // carries the hero alone from here (as at a sampled dispersive interface).
        wl.terminate_secondary();
        return Spectrum4(at_hero_index(m, wl).eval_and_pdf(ctx, wi, wo, pdf).x);
    }
    const Rgb f_rgb = m.eval_and_pdf(ctx, wi, wo, pdf);
    return spectral_eval(m, ctx, wi, wo, f_rgb, wl);
}

std::optional<BsdfSample> spectral_sample(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u,
                                          SampledWavelengths& wl) {
    if (is_dispersive(m.model)) [[unlikely]] {
        // Refraction (and reflection) of the hero wavelength with its index; the other lanes'
        // paths would part from it, so the path keeps the hero alone.
        wl.terminate_secondary();
        return at_hero_index(m, wl).sample(ctx, wi, u);
    }
    return m.sample(ctx, wi, u);
}

Spectrum4 spectral_sample_value(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const BsdfSample& s,
                                const SampledWavelengths& wl) {
    if (is_black(s.f)) return Spectrum4(0.0f);
    if (!s.delta) return spectral_eval(m, ctx, wi, s.wo, s.f, wl);
    MaterialModel storage;
    const LobeColour c = delta_lobe_colour(model_here(m, ctx, storage), m.spectra.get(), wi, s.wo, wl);
    const int k = c.rgb.x >= c.rgb.y && c.rgb.x >= c.rgb.z ? 0 : (c.rgb.y >= c.rgb.z ? 1 : 2);
    if (!(c.rgb[k] > 0)) return Spectrum4(0.0f);
    return c.spectral * (s.f[k] / c.rgb[k]);
}

}  // namespace pathlab
