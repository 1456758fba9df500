#include "integrators/common/spectral_shading.hpp"

#include <array>
#include <cmath>
#include <cstring>

#include "spectral/rgb_to_spectrum.hpp"
#include "spectral/tabulated.hpp"

namespace pathlab {
namespace {

// The table's lookup of rgb, through a direct-mapped per-thread cache keyed by rgb's bits.
SigmoidPolynomial lookup(const Vec3f& rgb) {
    struct Entry {
        std::array<uint32_t, 3> bits{};
        bool valid = false;
        SigmoidPolynomial poly;
    };
    thread_local std::array<Entry, 256> cache;
    std::array<uint32_t, 3> bits;
    std::memcpy(&bits[0], &rgb.x, 4);
    std::memcpy(&bits[1], &rgb.y, 4);
    std::memcpy(&bits[2], &rgb.z, 4);
    const uint64_t h = (uint64_t(bits[0]) * 0x9e3779b97f4a7c15ull) ^ (uint64_t(bits[1]) * 0xc2b2ae3d27d4eb4full) ^
                       (uint64_t(bits[2]) * 0x165667b19e3779f9ull);
    Entry& e = cache[size_t((h >> 32) & 255)];
    if (!e.valid || e.bits != bits) {
        e.poly = RgbToSpectrumTable::srgb()(rgb);
        e.bits = bits;
        e.valid = true;
    }
    return e.poly;
}

Spectrum4 at(const SigmoidPolynomial& poly, const SampledWavelengths& wl) {
    Spectrum4 s;
    for (int i = 0; i < kSpectrumLanes; ++i) s[i] = poly(wl[i]);
    return s;
}

}  // namespace

Spectrum4 unbounded_spectrum(const Rgb& rgb, const SampledWavelengths& wl) {
    // RgbUnboundedSpectrum: 2m sigmoid_{rgb / 2m}, m = max(rgb).
    const float m = std::max(std::max(rgb.x, rgb.y), rgb.z);
    if (!(m > 0)) return Spectrum4(0.0f);
    const float scale = 2 * m;
    return at(lookup(rgb / scale), wl) * scale;
}

Spectrum4 reflectance_spectrum(const Rgb& rgb, const SampledWavelengths& wl) {
    if (std::max(std::max(rgb.x, rgb.y), rgb.z) > 1) return unbounded_spectrum(rgb, wl);
    return at(lookup(rgb), wl);  // RgbAlbedoSpectrum
}

Spectrum4 illuminant_spectrum(const Rgb& rgb, const SampledWavelengths& wl) {
    if (is_black(rgb)) return Spectrum4(0.0f);
    return unbounded_spectrum(rgb, wl) * sample_d65_unit_luminance(wl);
}

Spectrum4 emission_spectrum(const Scene&, int, const Rgb& Le, const SampledWavelengths& wl) {
    return illuminant_spectrum(Le, wl);
}

Spectrum4 escaped_spectrum(const Scene& scene, const Vec3f& d, const SampledWavelengths& wl) {
    const int env = scene.environment_light();
    if (env < 0) return Spectrum4(0.0f);
    return emission_spectrum(scene, env, scene.escaped_radiance(d), wl);
}

Spectrum4 emitted_spectrum(const Scene& scene, const Intersection& hit, const Vec3f& w, const SampledWavelengths& wl) {
    const Rgb Le = emitted_radiance(scene, hit, w);
    if (is_black(Le)) return Spectrum4(0.0f);
    return emission_spectrum(scene, hit.light, Le, wl);
}

const char* spectral_material_names() {
    return "diffuse, phong, conductor, roughconductor, dielectric, roughdielectric, thindielectric";
}

std::string spectral_unsupported_model(const Material& m) {
    if (std::holds_alternative<PlasticMaterial>(m.model)) return "plastic";
    if (std::holds_alternative<RoughPlasticMaterial>(m.model)) return "roughplastic";
    if (std::holds_alternative<BlendMaterial>(m.model)) return "blendbsdf";
    if (std::holds_alternative<MaskMaterial>(m.model)) return "mask";
    return "";
}

namespace {

// The Fresnel reflectance of a conductor, times its specular reflectance, per lane.
Spectrum4 conductor_reflectance(const Rgb& specular_reflectance, const Rgb& eta, const Rgb& k, float cos_i,
                                const SampledWavelengths& wl) {
    const Spectrum4 R = reflectance_spectrum(specular_reflectance, wl);
    const Spectrum4 e = unbounded_spectrum(eta, wl), kk = unbounded_spectrum(k, wl);
    Spectrum4 F;
    for (int i = 0; i < kSpectrumLanes; ++i) F[i] = fresnel_conductor(cos_i, e[i], kk[i]);
    return R * F;
}

Spectrum4 eval_model(const MaterialModel& model, const Vec3f& wi, const Vec3f& wo, const Rgb& f_rgb, const SampledWavelengths& wl) {
    if (const auto* p = std::get_if<PhongMaterial>(&model)) {
        // rho_d / pi + rho_s (n + 2) cos^n / (2 pi), as phong.hpp.
        Spectrum4 f = reflectance_spectrum(p->diffuse, wl) * kInvPi;
        if (!is_black(p->specular)) {
            const float cos_alpha = dot(PhongMaterial::mirror(wi), wo);
            if (cos_alpha > 0)
                f += reflectance_spectrum(p->specular, wl) * ((p->exponent + 2) * std::pow(cos_alpha, p->exponent) * (1 / (2 * kPi)));
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
        const float cos_ih = dot(wi, normalize(wi + wo));
        return conductor_reflectance(c->specular_reflectance, c->eta, c->k, cos_ih, wl) * g;
    }
    // Models without a colour parameter (the dielectrics): their RGB value is grey.
    return Spectrum4(f_rgb.x);
}

}  // namespace

Spectrum4 spectral_eval(const ShadingPoint& sp, const Vec3f& wo, const Rgb& f_rgb, const SampledWavelengths& wl) {
    if (is_black(f_rgb)) return Spectrum4(0.0f);
    if (sp.material->varies) return eval_model(sp.material->model_at(sp.uv), sp.wi, wo, f_rgb, wl);
    return eval_model(sp.material->model, sp.wi, wo, f_rgb, wl);
}

Spectrum4 spectral_eval_and_pdf(const ShadingPoint& sp, const Vec3f& wo, SampledWavelengths& wl, float& pdf) {
    const Rgb f_rgb = sp.material->eval_and_pdf(sp, sp.wi, wo, pdf);
    return spectral_eval(sp, wo, f_rgb, wl);
}

std::optional<BsdfSample> spectral_sample(const ShadingPoint& sp, const Vec2f& u, SampledWavelengths& wl) {
    if (const auto* d = std::get_if<DielectricMaterial>(&sp.material->model); d && d->dispersion) [[unlikely]] {
        DielectricMaterial hero = *d;
        hero.int_ior = float((*d->dispersion)(wl[0]));
        wl.terminate_secondary();
        return hero.sample(sp.wi, u);
    }
    return sp.material->sample(sp, sp.wi, u);
}

Spectrum4 spectral_sample_value(const ShadingPoint& sp, const BsdfSample& s, const SampledWavelengths& wl) {
    if (is_black(s.f)) return Spectrum4(0.0f);
    if (!s.delta) return spectral_eval(sp, s.wo, s.f, wl);
    const auto delta_value = [&](const MaterialModel& model) {
        if (const auto* c = std::get_if<ConductorMaterial>(&model))
            return conductor_reflectance(c->specular_reflectance, c->eta, c->k, sp.wi.z, wl) / s.wo.z;
        return Spectrum4(s.f.x);  // the dielectrics' delta coefficients are grey
    };
    if (sp.material->varies) return delta_value(sp.material->model_at(sp.uv));
    return delta_value(sp.material->model);
}

}  // namespace pathlab
