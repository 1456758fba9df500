// point: an isotropic point light of intensity I (W/sr per channel); power 4 pi I.
//
// XML (Mitsuba 3): intensity (rgb, default 1), position (point, default 0 0 0) or to_world.
//
// Incident sampling: the one direction towards the light, Le = I / d^2 (delta). Emission: the
// light's position (delta position, pdfA = 1) and a uniformly distributed direction
// (pdfW = 1 / (4 pi)), Le = I.
#pragma once

#include <optional>

#include "core/sampling.hpp"
#include "lights/light_sample.hpp"
#include "core/properties.hpp"

namespace pathlab {

struct PointLight {
    Vec3f position;
    Rgb intensity;

    static constexpr uint32_t flags = kLightDeltaPosition;

    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f) const {
        const Vec3f d = position - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        return LightSample{d / dist, dist, position, Vec3f(0.0f), intensity / dist2, 1.0f, true};
    }
    std::optional<EmissionSample> sample_emission(Vec2f, Vec2f u_dir, const SceneSphere&) const {
        const Vec3f d = square_to_uniform_sphere(u_dir);
        return EmissionSample{position, d, d, intensity, 1.0f, 1.0f, uniform_sphere_pdf()};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f&, const Vec3f&, const SceneSphere&) const {
        return {1.0f, uniform_sphere_pdf()};
    }
    float power(const SceneSphere&) const { return 4 * kPi * mean(intensity); }
};

inline const PluginInfo& point_plugin() {
    static const PluginInfo info{"emitter", "point", "an isotropic point light",
                                 {{"position", ParamType::Point, "0, 0, 0", "where it is (moved by to_world)"},
                                  {"intensity", ParamType::Rgb, "1", "radiant intensity I, W/sr (power 4 pi I)"},
                                  {"to_world", ParamType::Transform, "", "placement", "toWorld"}}};
    return info;
}
inline PointLight read_point_light(Properties& p) {
    Vec3f position = p.get_point("position");
    if (const auto t = p.get_transform("to_world")) position = Vec3f(t->point(Vec3d(position)));
    return PointLight{position, p.get_rgb("intensity")};
}

}  // namespace pathlab
