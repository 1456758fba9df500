// thindielectric: a thin slab of glass (a window pane, a soap bubble): light is reflected by
// both of its faces, and what passes goes straight through (the two refractions cancel).
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   int_ior   float or string  the slab's index of refraction, or a name   default bk7 (1.5046)
//   ext_ior   float or string  the outside's                               default air (1.000277)
// Symmetric: both sides are the same (it needs no twosided).
//
// With the Fresnel reflectance R of one face, the slab reflects R' = R + (1 - R)^2 R / (1 - R^2)
// = 2R / (1 + R) (all the internal reflections summed) and transmits T' = 1 - R'. Both lobes
// are Dirac deltas (see bsdf_sample.hpp): reflection with probability R', transmission along
// -wi with 1 - R'. No direction is bent, so there is no (eta_wi / eta_wo)^2 factor.
#pragma once

#include <cmath>
#include <optional>

#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/dielectric.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/ior.hpp"

namespace pathlab {

struct ThinDielectricMaterial {
    float int_ior = 1.5046f;
    float ext_ior = 1.000277f;

    // The slab's reflectance R' at |cos| of the incident direction.
    float reflectance(float cos_i) const {
        const float R = fresnel_dielectric(cos_i, int_ior / ext_ior);
        return R < 1 ? 2 * R / (1 + R) : 1.0f;
    }

    Rgb eval(const Vec3f&, const Vec3f&) const { return Rgb(0.0f); }
    float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        const float cos_i = std::abs(wi.z);
        if (!(cos_i > 0)) return std::nullopt;
        const float R = reflectance(cos_i);
        if (u.x < R) return BsdfSample{Vec3f(-wi.x, -wi.y, wi.z), Rgb(R / cos_i), R, true, kLobeSpecular | kLobeReflection};
        return BsdfSample{-wi, Rgb((1 - R) / cos_i), 1 - R, true, kLobeSpecular | kLobeTransmission | kLobeNull};
    }
};

inline const PluginInfo& thindielectric_plugin() {
    static const PluginInfo info{"bsdf", "thindielectric",
                                 "a thin glass slab: reflection 2R / (1 + R) from both faces, the rest straight through (two-sided by itself)",
                                 {{"int_ior", ParamType::FloatOrString, "bk7", "the slab's index of refraction, a number or a name: " + kIorNames, "intIOR"},
                                  kExtIorParam}};
    return info;
}
inline ThinDielectricMaterial read_thindielectric(Properties& p) {
    return ThinDielectricMaterial{read_ior(p, "int_ior"), read_ior(p, "ext_ior")};
}

}  // namespace pathlab
