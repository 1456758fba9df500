// spot: a point light emitting into a cone (Mitsuba 3's spot emitter), at the origin of its
// frame and pointing along its +z axis (to_world, e.g. a lookat, places and aims it).
//
// XML (Mitsuba 3): intensity (rgb, default 1), cutoff_angle (degrees, default 20), beam_width
// (degrees, default 3/4 of cutoff_angle), to_world. Mitsuba 3's projected `texture` is not
// supported yet (refused with an error).
//
// Falloff, Mitsuba 3's linear ramp in angle: the radiant intensity at angle theta from the axis
// is I * falloff(theta) with falloff = 1 for theta <= beam_width, (cutoff - theta) /
// (cutoff - beam_width) between them, 0 from cutoff_angle on. Power:
//   2 pi I [1 - (sin c - sin b) / (c - b)]  (c = cutoff, b = beam width; 2 pi I (1 - cos c) if b = c).
//
// Incident sampling: the one direction towards the light, Le = I falloff / d^2 (delta).
// Emission: the light's position (delta position, pdfA = 1) and a direction uniformly inside the
// cutoff cone (pdfW = 1 / (2 pi (1 - cos c))), Le = I falloff.
#pragma once

#include <cmath>
#include <optional>

#include "core/frame.hpp"
#include "core/properties.hpp"
#include "core/sampling.hpp"
#include "lights/light_sample.hpp"

namespace pathlab {

struct SpotLight {
    Vec3f position;
    Frame frame;  // frame.n: the axis
    Rgb intensity;
    float cutoff = 0, beam_width = 0;  // radians
    float cos_cutoff = 1, cos_beam_width = 1;

    static constexpr uint32_t flags = kLightDeltaPosition;

    SpotLight() = default;
    SpotLight(const Vec3f& position_, const Vec3f& axis, const Rgb& intensity_, float cutoff_degrees, float beam_width_degrees)
        : position(position_), frame(axis), intensity(intensity_), cutoff(cutoff_degrees * kPi / 180),
          beam_width(beam_width_degrees * kPi / 180), cos_cutoff(std::cos(cutoff)), cos_beam_width(std::cos(beam_width)) {}

    // The falloff at a unit direction in the light's frame (z along the axis).
    float falloff(const Vec3f& local) const {
        if (!(local.z > cos_cutoff)) return 0.0f;
        if (local.z >= cos_beam_width) return 1.0f;
        const float theta = std::acos(std::min(local.z, 1.0f));
        return std::clamp((cutoff - theta) / (cutoff - beam_width), 0.0f, 1.0f);
    }
    float falloff_world(const Vec3f& w) const { return falloff(frame.to_local(w)); }

    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f) const {
        const Vec3f d = position - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const float f = falloff_world(-d / dist);
        if (f == 0) return std::nullopt;
        return LightSample{d / dist, dist, position, Vec3f(0.0f), intensity * (f / dist2), 1.0f, true};
    }
    std::optional<EmissionSample> sample_emission(Vec2f, Vec2f u_dir, const SceneSphere&) const {
        const Vec3f local = square_to_uniform_cone(u_dir, cos_cutoff);
        const Vec3f d = frame.to_world(local);
        return EmissionSample{position, d, d, intensity * falloff(local), 1.0f, 1.0f, uniform_cone_pdf(cos_cutoff)};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f&, const Vec3f& dir, const SceneSphere&) const {
        return {1.0f, dot(dir, frame.n) >= cos_cutoff ? uniform_cone_pdf(cos_cutoff) : 0.0f};
    }
    // The integral of falloff over the sphere (power = I times it).
    double falloff_solid_angle() const {
        const double c = cutoff, b = beam_width;
        if (c - b < 1e-6) return 2 * M_PI * (1 - std::cos(c));
        return 2 * M_PI * (1 - (std::sin(c) - std::sin(b)) / (c - b));
    }
    float power(const SceneSphere&) const { return float(mean(intensity) * falloff_solid_angle()); }
};

inline const PluginInfo& spot_plugin() {
    static const PluginInfo info{"emitter", "spot", "a spot light: a point light emitting into a cone, with a linear falloff",
                                 {{"intensity", ParamType::Rgb, "1", "radiant intensity I on the axis, W/sr"},
                                  {"cutoff_angle", ParamType::Float, "20", "degrees from the axis beyond which it is black"},
                                  {"beam_width", ParamType::Float, "", "degrees from the axis of full intensity (default: 3/4 of cutoff_angle)"},
                                  {"to_world", ParamType::Transform, "", "placement: at the origin, pointing along +z (e.g. a lookat)"}},
                                 "Mitsuba 3's projected `texture` is not supported yet (an error)."};
    return info;
}
inline SpotLight read_spot_light(Properties& p) {
    const float cutoff = p.get_float("cutoff_angle");
    if (!(cutoff > 0 && cutoff <= 180)) p.fail("cutoff_angle", "a spot's cutoff_angle must be in (0, 180] degrees");
    const float beam = p.has("beam_width") ? p.get_float("beam_width") : cutoff * 0.75f;
    if (!(beam >= 0 && beam <= cutoff)) p.fail("beam_width", "a spot's beam_width must be in [0, cutoff_angle] degrees");
    Vec3d position(0.0), axis(0, 0, 1);
    if (const auto t = p.get_transform("to_world")) position = t->point(position), axis = t->vector(axis);
    if (!(length(axis) > 0)) p.fail("to_world", "the to_world of a spot emitter turns its axis to nothing");
    return SpotLight(Vec3f(position), Vec3f(normalize(axis)), p.get_rgb("intensity"), cutoff, beam);
}

}  // namespace pathlab
