// directional: a light infinitely far away (the sun), irradiance E on a surface facing it,
// travelling along one direction. Power pi R^2 E over the scene's bounding disk.
//
// XML (Mitsuba 3): irradiance (rgb, default 1), direction (vector, default 0 0 1) or to_world.
//
// Incident sampling: the one direction towards the light (delta). Emission: that direction
// (delta direction, pdfW = 1) from a point uniformly on the scene's entry disk (see
// constant.hpp), Le = E.
#pragma once

#include <optional>

#include "lights/constant.hpp"
#include "lights/light_sample.hpp"
#include "core/properties.hpp"

namespace pathlab {

struct DirectionalLight {
    Vec3f direction;  // unit direction in which the light travels
    Rgb irradiance;

    static constexpr uint32_t flags = kLightDeltaDirection | kLightInfinite;

    std::optional<LightSample> sample_li(const Vec3f&, Vec2f) const {
        return LightSample{-direction, kInf, Vec3f(0.0f), Vec3f(0.0f), irradiance, 1.0f, true};
    }
    std::optional<EmissionSample> sample_emission(Vec2f u_pos, Vec2f, const SceneSphere& s) const {
        return EmissionSample{point_on_entry_disk(s, direction, u_pos), direction, direction, irradiance, 1.0f,
                              entry_disk_pdfA(s), 1.0f};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f&, const Vec3f&, const SceneSphere& s) const {
        return {entry_disk_pdfA(s), 1.0f};
    }
    float power(const SceneSphere& s) const { return kPi * s.radius * s.radius * mean(irradiance); }
};

inline const PluginInfo& directional_plugin() {
    static const PluginInfo info{"emitter", "directional", "a light infinitely far away, along one direction (the sun)",
                                 {{"direction", ParamType::Point, "0, 0, 1", "the direction the light travels in (turned by to_world)"},
                                  {"irradiance", ParamType::Rgb, "1", "irradiance E on a surface facing the light, W/m^2"},
                                  {"to_world", ParamType::Transform, "", "orientation", "toWorld"}}};
    return info;
}
inline DirectionalLight read_directional_light(Properties& p) {
    Vec3d dir(p.get_point("direction"));
    if (const auto t = p.get_transform("to_world")) dir = t->vector(dir);
    if (!(length(dir) > 0)) p.fail("a directional emitter needs a non-zero direction");
    return DirectionalLight{Vec3f(normalize(dir)), p.get_rgb("irradiance")};
}

}  // namespace pathlab
