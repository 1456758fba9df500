// dielectric: a smooth interface between two dielectrics (glass, water), with Fresnel
// reflection and refraction.
//
// XML (Mitsuba 3 names; Mitsuba 0.6 camelCase spellings accepted):
//   int_ior   float or string  interior index of refraction, or a name (bk7, water, ...)  default bk7 (1.5046)
//   ext_ior   float or string  exterior index of refraction                            default air (1.000277)
// The exterior is the side the normal points to. Cannot be wrapped in twosided: both of its
// sides matter.
//
// Reflection is chosen with probability F (Fresnel), refraction with 1 - F; both lobes are
// Dirac deltas (see bsdf_sample.hpp). Radiance keeps L / eta^2 invariant across the interface,
// so a refracted sample carries the weight (eta_wi / eta_wo)^2 (indices on the sides of wi
// and wo); a path that enters and leaves a body picks up factors that cancel.
#pragma once

#include <cmath>
#include <optional>

#include "bsdfs/bsdf_sample.hpp"
#include "bsdfs/fresnel.hpp"
#include "bsdfs/ior.hpp"

namespace pathlab {

struct DielectricMaterial {
    float int_ior = 1.5046f;  // Mitsuba's default (BK7 glass)
    float ext_ior = 1.000277f;

    Rgb eval(const Vec3f&, const Vec3f&) const { return Rgb(0.0f); }
    float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
    std::optional<BsdfSample> sample(const Vec3f& wi, Vec2f u) const {
        const bool outside = wi.z > 0;
        const float eta_wi = outside ? ext_ior : int_ior, eta_other = outside ? int_ior : ext_ior;
        const float cos_i = std::abs(wi.z);
        float cos_t = 0;
        const float F = fresnel_dielectric(cos_i, eta_other / eta_wi, &cos_t);
        if (u.x < F) {
            const Vec3f wo(-wi.x, -wi.y, wi.z);
            return BsdfSample{wo, Rgb(F / cos_i), F, true, kLobeSpecular | kLobeReflection};
        }
        // Refraction: wo on the other side, tangential part scaled by eta_wi / eta_other.
        const float r = eta_wi / eta_other;
        const Vec3f wo(-wi.x * r, -wi.y * r, outside ? -cos_t : cos_t);
        const float scale = r * r;  // (eta_wi / eta_wo)^2
        return BsdfSample{wo, Rgb((1 - F) * scale / cos_t), 1 - F, true, kLobeSpecular | kLobeTransmission};
    }
};

inline const ParamInfo kIntIorParam{"int_ior", ParamType::FloatOrString, "bk7",
                                    "interior index of refraction, a number or a name: " + kIorNames, "intIOR"};
inline const ParamInfo kExtIorParam{"ext_ior", ParamType::FloatOrString, "air", "exterior index of refraction (the normal's side)",
                                    "extIOR"};

inline const PluginInfo& dielectric_plugin() {
    static const PluginInfo info{"bsdf", "dielectric", "a smooth interface between two dielectrics (glass, water): Fresnel reflection and refraction",
                                 {kIntIorParam, kExtIorParam}};
    return info;
}
inline DielectricMaterial read_dielectric(Properties& p) {
    const float int_ior = read_ior(p, "int_ior"), ext_ior = read_ior(p, "ext_ior");
    return DielectricMaterial{int_ior, ext_ior};
}

}  // namespace pathlab
