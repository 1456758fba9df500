// constant: a constant environment, radiance L arriving from every direction (rays that
// escape the scene see it). Its power is taken as that of a disk of the scene's bounding
// radius R: pi R^2 * pi L (for choosing lights by power).
//
// XML (Mitsuba 3): radiance (rgb, default 1).
//
// Incident sampling: directions uniformly over the sphere (pdfW = 1 / (4 pi)). Emission: a
// direction d uniformly over the sphere, and an origin uniformly on the disk of radius R
// perpendicular to d, centred R before the scene's centre (pdfA = 1 / (pi R^2)); every ray
// that meets the scene is covered.
#pragma once

#include <optional>

#include "core/frame.hpp"
#include "core/sampling.hpp"
#include "lights/light_sample.hpp"
#include "core/properties.hpp"

namespace pathlab {

// A point on the disk of radius R perpendicular to d, centred R upstream of the scene's
// centre: where light paths from lights at infinity start.
inline Vec3f point_on_entry_disk(const SceneSphere& s, const Vec3f& d, Vec2f u) {
    const Vec2f q = square_to_concentric_disk(u);
    const Frame f(d);
    return s.center + (f.s * q.x + f.t * q.y - d) * s.radius;
}
inline float entry_disk_pdfA(const SceneSphere& s) { return 1 / (kPi * s.radius * s.radius); }

struct EnvironmentLight {
    Rgb radiance;

    static constexpr uint32_t flags = kLightInfinite;

    std::optional<LightSample> sample_li(const Vec3f&, Vec2f u) const {
        return LightSample{square_to_uniform_sphere(u), kInf, Vec3f(0.0f), Vec3f(0.0f), radiance, uniform_sphere_pdf(), false};
    }
    // Solid-angle density with which sample_li produces the direction w (towards the environment).
    float pdf_li(const Vec3f& = {}) const { return uniform_sphere_pdf(); }
    // Radiance arriving along a ray that escapes in direction w.
    Rgb Le(const Vec3f& = {}) const { return radiance; }
    std::optional<EmissionSample> sample_emission(Vec2f u_pos, Vec2f u_dir, const SceneSphere& s) const {
        const Vec3f d = square_to_uniform_sphere(u_dir);
        return EmissionSample{point_on_entry_disk(s, d, u_pos), d, d, radiance, 1.0f, entry_disk_pdfA(s), uniform_sphere_pdf()};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f&, const Vec3f&, const SceneSphere& s) const {
        return {entry_disk_pdfA(s), uniform_sphere_pdf()};
    }
    float power(const SceneSphere& s) const { return kPi * s.radius * s.radius * kPi * mean(radiance); }
};

inline const PluginInfo& constant_plugin() {
    static const PluginInfo info{"emitter", "constant", "a constant environment: the same radiance from every direction",
                                 {{"radiance", ParamType::Rgb, "1", "radiance L"}}};
    return info;
}
inline EnvironmentLight read_constant_light(Properties& p) { return EnvironmentLight{p.get_rgb("radiance")}; }

}  // namespace pathlab
