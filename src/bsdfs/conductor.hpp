// conductor: a smooth metal, a perfect specular reflector with the Fresnel reflectance of a
// conductor (complex index of refraction, per RGB channel).
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   material              string  a metal by name: none, Au, Ag, Cu, Al, Cr, a-C   default none
//   eta, k                rgb     complex index of refraction, instead of material default 0, 1
//   specular_reflectance  rgb     scales the reflectance (not physical)            default 1
// material="none" (eta = 0, k = 1) reflects everything at every angle: a perfect mirror.
// One-sided (black from behind) unless wrapped in twosided.
//
// The lobe is a Dirac delta: eval() and pdf() are zero, sample() returns the mirror direction
// with f = R F(cos) / cos and pdfW = 1 as delta coefficients (see bsdf_sample.hpp).
#pragma once

#include <optional>

#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/ior.hpp"

namespace pathlab {

struct ConductorMaterial {
    Rgb eta{0.0f}, k{1.0f};
    Rgb specular_reflectance{1.0f};
    const MeasuredConductor* measured = nullptr;  // spectral mode's eta, k of a named metal (ior.hpp)

    Rgb fresnel(float cos_i) const { return specular_reflectance * fresnel_conductor(cos_i, eta, k); }

    Rgb eval(const Vec3f&, const Vec3f&) const { return Rgb(0.0f); }
    float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f) const {
        if (wi.z <= 0) return std::nullopt;
        const Vec3f wo(-wi.x, -wi.y, wi.z);
        return BsdfSample{wo, fresnel(wi.z) / wo.z, 1.0f, true, kLobeSpecular | kLobeReflection};
    }

    static constexpr int kSlotSpecularReflectance = 0;  // the parameter a texture may give
    void set_texel(int, const Rgb& v) { specular_reflectance = v; }
};

inline const PluginInfo& conductor_plugin() {
    static const PluginInfo info{"bsdf", "conductor", "a smooth metal: a perfect specular reflector with the conductor's Fresnel reflectance",
                                 {kConductorMaterialParam, kConductorEtaParam, kConductorKParam,
                                  {"specular_reflectance", ParamType::Rgb, "1", "scales the reflectance (not physical)", "specularReflectance",
                                   ConductorMaterial::kSlotSpecularReflectance}}};
    return info;
}
inline ConductorMaterial read_conductor(Properties& p) {
    const ComplexIor ior = read_conductor_ior(p);
    return ConductorMaterial{ior.eta, ior.k, p.get_rgb("specular_reflectance"), ior.measured};
}

}  // namespace pathlab
