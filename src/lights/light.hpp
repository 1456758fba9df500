// Light sources: one interface that every light type implements (a closed set, dispatched
// with std::visit in the hot loop). Each type lives in its own header:
//   point.hpp (point), spot.hpp (spot), ies.hpp (ies: a point light with a photometric
//   profile), triangle.hpp and sphere.hpp (area emitters on shapes), constant.hpp (constant
//   environment), envmap.hpp (environment map), directional.hpp (directional).
// Every type provides, with the measures of light_sample.hpp:
//   flags                                 kLightDeltaPosition, kLightDeltaDirection, kLightInfinite, kLightSurface
//   sample_li(p, u) -> LightSample        incident illumination at p (direction, radiance, pdfW)
//   pdf_li(...)                           its density (surface lights: of a point q with normal n
//                                         seen from p; the environment: of a direction)
//   Le(w)                                 radiance for a ray that hits it (environment; surfaces:
//                                         surface_radiance below)
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
#include "lights/envmap.hpp"
#include "lights/ies.hpp"
#include "lights/point.hpp"
#include "lights/projector.hpp"
#include "lights/sphere.hpp"
#include "lights/spot.hpp"
#include "lights/triangle.hpp"

namespace pathlab {

using Light = std::variant<PointLight, TriangleLight, SphereLight, EnvironmentLight, DirectionalLight, EnvMapLight, SpotLight,
                           IesLight, ProjectorLight>;

inline uint32_t light_flags(const Light& light) {
    return std::visit([](const auto& l) { return l.flags; }, light);
}
inline bool is_delta_light(const Light& light) {
    return (light_flags(light) & (kLightDeltaPosition | kLightDeltaDirection)) != 0;
}

// Radiance of a surface emitter (triangle or sphere) at the point with texture coordinates uv
// (a textured emitter's), black for other lights.
inline Rgb surface_radiance(const Light& light, const Vec2f& uv) {
    if (const auto* t = std::get_if<TriangleLight>(&light)) return t->radiance_at(uv);
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

// The environment (constant or a map; see Scene::environment_light): radiance arriving along
// an escaped ray's direction w, and the solid-angle density with which light sampling produces
// w (without the light's selection probability). Black and 0 for other lights.
inline Rgb environment_radiance(const Light& light, const Vec3f& w) {
    if (const auto* c = std::get_if<EnvironmentLight>(&light)) return c->Le(w);
    if (const auto* m = std::get_if<EnvMapLight>(&light)) return m->Le(w);
    return Rgb(0.0f);
}
inline float environment_pdf_li(const Light& light, const Vec3f& w) {
    if (const auto* c = std::get_if<EnvironmentLight>(&light)) return c->pdf_li(w);
    if (const auto* m = std::get_if<EnvMapLight>(&light)) return m->pdf_li(w);
    return 0.0f;
}
inline bool is_environment(const Light& light) {
    return std::holds_alternative<EnvironmentLight>(light) || std::holds_alternative<EnvMapLight>(light);
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
