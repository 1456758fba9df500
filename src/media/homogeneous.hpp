// homogeneous: a medium with the same coefficients everywhere (fog, milk, a tinted liquid).
//
// XML (Mitsuba 3): sigma_t (rgb, default 1) and albedo (rgb, default 0.75), or, as Mitsuba 0.6
// wrote them, sigma_a and sigma_s (absorption and scattering; sigma_t = sigma_a + sigma_s);
// scale (float, default 1) multiplies the coefficients (a unit change: the coefficients are per
// scene unit of length); a nested <phase> (default isotropic).
#pragma once

#include "core/properties.hpp"
#include "media/phase.hpp"

namespace pathlab {

struct HomogeneousMedium {
    Rgb sigma_t{1.0f};  // extinction, per unit length
    Rgb sigma_s{0.75f};  // scattering (albedo x sigma_t)
    PhaseFunction phase;
};

inline const PluginInfo& homogeneous_plugin() {
    static const PluginInfo info{
        "medium", "homogeneous", "the same coefficients everywhere",
        {{"sigma_t", ParamType::Rgb, "1", "extinction coefficient, per unit length", "sigmaT"},
         {"albedo", ParamType::Rgb, "0.75", "single-scattering albedo sigma_s / sigma_t, in [0, 1]"},
         {"sigma_a", ParamType::Rgb, "", "absorption coefficient (with sigma_s, instead of sigma_t and albedo)", "sigmaA"},
         {"sigma_s", ParamType::Rgb, "", "scattering coefficient (with sigma_a)", "sigmaS"},
         {"scale", ParamType::Float, "1", "multiplies the coefficients"}},
        "A nested `<phase>` sets the phase function (default isotropic)."};
    return info;
}

inline HomogeneousMedium read_homogeneous_medium(Properties& p) {
    HomogeneousMedium m;
    const float scale = p.get_float("scale");
    if (!(scale >= 0) || !std::isfinite(scale)) p.fail("scale", "scale must be finite and not negative");
    if (p.has("sigma_a") || p.has("sigma_s")) {
        if (p.has("sigma_t") || p.has("albedo")) p.fail("give either sigma_a and sigma_s or sigma_t and albedo, not both");
        if (!p.has("sigma_a") || !p.has("sigma_s")) p.fail("sigma_a and sigma_s go together");
        const Rgb a = p.get_rgb("sigma_a"), s = p.get_rgb("sigma_s");
        m.sigma_t = (a + s) * scale;
        m.sigma_s = s * scale;
    } else {
        const Rgb albedo = p.get_rgb("albedo");
        if (max_component(albedo) > 1) p.fail("albedo", "albedo must lie in [0, 1]");
        m.sigma_t = p.get_rgb("sigma_t") * scale;
        m.sigma_s = albedo * m.sigma_t;
    }
    return m;
}

}  // namespace pathlab
