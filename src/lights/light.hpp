// Light sources: one interface that every light type implements (a closed set, dispatched
// with std::visit in the hot loop). Each type lives in its own header:
//   point.hpp (point), triangle.hpp and sphere.hpp (area emitters on shapes),
//   constant.hpp (constant environment), directional.hpp (directional).
// Every type provides, with the measures of light_sample.hpp:
//   flags                                 kLightDeltaPosition, kLightDeltaDirection, kLightInfinite, kLightSurface
//   sample_li(p, u) -> LightSample        incident illumination at p (direction, radiance, pdfW)
//   pdf_li(...)                           its density (surface lights: of a point q with normal n
//                                         seen from p; the environment: of a direction)
//   emitted(w) / Le(w)                    radiance for a ray that hits it (surface / environment)
//   sample_emission(u_pos, u_dir, sphere) an origin and a direction for a light path
//   pdf_emission(origin, normal, dir, sphere) -> {pdfA, pdfW}
//   power(sphere)                         for choosing lights by power (light_distribution.hpp)
// To add a light: one header here, one alternative in the variant below, and its scene-file
// reader in the lights registry.
#pragma once

#include <optional>
#include <variant>

#include "lights/constant.hpp"
#include "lights/directional.hpp"
#include "lights/point.hpp"
#include "lights/sphere.hpp"
#include "lights/triangle.hpp"

namespace pathlab {

using Light = std::variant<PointLight, TriangleLight, SphereLight, EnvironmentLight, DirectionalLight>;

inline uint32_t light_flags(const Light& light) {
    return std::visit([](const auto& l) { return l.flags; }, light);
}
inline bool is_delta_light(const Light& light) {
    return (light_flags(light) & (kLightDeltaPosition | kLightDeltaDirection)) != 0;
}

// Radiance of a surface emitter (triangle or sphere), black for other lights.
inline Rgb surface_radiance(const Light& light) {
    if (const auto* t = std::get_if<TriangleLight>(&light)) return t->radiance;
    if (const auto* s = std::get_if<SphereLight>(&light)) return s->radiance;
    return Rgb(0.0f);
}
// Solid-angle density with which sampling the surface emitter `light` from p produces the
// point q with normal n (0 for other lights).
inline float surface_light_pdf_li(const Light& light, const Vec3f& p, const Vec3f& q, const Vec3f& n) {
    if (const auto* t = std::get_if<TriangleLight>(&light)) return t->pdf_li(p, q);
    if (const auto* s = std::get_if<SphereLight>(&light)) return s->pdf_li(p, q, n);
    return 0.0f;
}

inline std::optional<LightSample> sample_light(const Light& light, const Vec3f& p, const Vec2f& u) {
    return std::visit([&](const auto& l) { return l.sample_li(p, u); }, light);
}
inline std::optional<EmissionSample> sample_emission(const Light& light, const Vec2f& u_pos, const Vec2f& u_dir,
                                                     const SceneSphere& sphere) {
    return std::visit([&](const auto& l) { return l.sample_emission(u_pos, u_dir, sphere); }, light);
}
inline EmissionPdf pdf_emission(const Light& light, const Vec3f& origin, const Vec3f& normal, const Vec3f& dir,
                                const SceneSphere& sphere) {
    return std::visit([&](const auto& l) { return l.pdf_emission(origin, normal, dir, sphere); }, light);
}
inline float light_power(const Light& light, const SceneSphere& sphere) {
    return std::visit([&](const auto& l) { return l.power(sphere); }, light);
}

}  // namespace pathlab
