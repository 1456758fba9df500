#include "integrators/bidir/bidir_spectral_shading.hpp"

#include "integrators/common/spectral_shading.hpp"

namespace pathlab {
namespace {

// The models whose spectral value spectral_shading computes from the radiance-mode model (so
// without importance mode's factor); the others' values are grey, taken from the RGB value.
bool recoloured(const MaterialModel& m) {
    return std::holds_alternative<PhongMaterial>(m) || std::holds_alternative<ConductorMaterial>(m) ||
           std::holds_alternative<RoughConductorMaterial>(m);
}

// The factor importance transport applies to a recoloured model's value (1 in radiance mode).
float adjoint_factor(const ShadingPoint& sp, const Vec3f& wo) {
    if (sp.mode != TransportMode::Importance || !recoloured(sp.material->model)) return 1.0f;
    return sp.material->importance_factor(sp, sp.wi, wo);
}

}  // namespace

std::optional<BsdfSample> bidir_spectral_sample(const ShadingPoint& sp, const Vec2f& u, SampledWavelengths& wl) {
    if (const auto* d = std::get_if<DielectricMaterial>(&sp.material->model); d && d->dispersion) [[unlikely]] {
        // The same material with the hero's index (Material::importance_factor reads it too).
        Material hero = *sp.material;
        std::get<DielectricMaterial>(hero.model).int_ior = float((*d->dispersion)(wl[0]));
        wl.terminate_secondary();
        return hero.sample(sp, sp.wi, u);
    }
    return sp.material->sample(sp, sp.wi, u);
}

Spectrum4 bidir_spectral_sample_value(const ShadingPoint& sp, const BsdfSample& s, const SampledWavelengths& wl) {
    const Spectrum4 f = spectral_sample_value(sp, s, wl);
    return f.is_black() ? f : f * adjoint_factor(sp, s.wo);
}

Spectrum4 bidir_spectral_eval(const ShadingPoint& sp, const Vec3f& wo, const Rgb& f_rgb, const SampledWavelengths& wl) {
    const Spectrum4 f = spectral_eval(sp, wo, f_rgb, wl);
    return f.is_black() ? f : f * adjoint_factor(sp, wo);
}

}  // namespace pathlab
