// ies: a point light whose intensity follows an IES photometric file (ANSI/IESNA LM-63, type C;
// ies_profile.hpp reads it), placed and aimed by to_world.
//
// XML: filename (the .ies file), intensity (rgb, default 1: a scale), to_world (a rotation and
// a translation; the profile's nadir, vertical angle 0, points along the frame's +z as a spot
// light does, horizontal angle 0 along +x and 90 along -y, so a lookat aims the nadir at its
// target).
//
// Radiometry: the file gives luminous intensity in candela (lm/sr). pathlab renders RGB
// radiometric quantities, so each channel's radiant intensity is
//     I = intensity * candela / 683   (W/sr),
// 683 lm/W being the luminous efficacy of monochromatic 555 nm light, the factor that defines
// the candela: a white (1, 1, 1) luminaire of 1000 lm emits 1000 / 683 W per channel. Power:
// mean(intensity) * flux / 683, the flux being the exact integral of the interpolated profile.
//
// Incident sampling: the one direction towards the light, Le = I(direction) / d^2 (delta).
// Emission: the light's position (delta position, pdfA = 1) and a direction sampled by the
// profile (IesDistribution::sample: piecewise constant over the angular grid, per unit solid
// angle), Le = I(direction).
#pragma once

#include <memory>
#include <optional>

#include "core/frame.hpp"
#include "core/properties.hpp"
#include "lights/ies_profile.hpp"
#include "lights/light_sample.hpp"
#include "lights/placement.hpp"

namespace pathlab {

constexpr float kLumensPerWatt = 683.0f;

struct IesLight {
    Vec3f position;
    Frame frame;     // the luminaire's frame: n is the nadir
    Rgb scale;       // intensity / 683: W/sr per candela
    std::shared_ptr<const IesDistribution> profile;

    static constexpr uint32_t flags = kLightDeltaPosition;

    // Radiant intensity (W/sr) towards the world direction w (unit).
    Rgb intensity_towards(const Vec3f& w) const { return scale * profile->candela(frame.to_local(w)); }

    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f) const {
        const Vec3f d = position - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const Rgb I = intensity_towards(-d / dist);
        if (is_black(I)) return std::nullopt;
        return LightSample{d / dist, dist, position, Vec3f(0.0f), I / dist2, 1.0f, true};
    }
    std::optional<EmissionSample> sample_emission(Vec2f, Vec2f u_dir, const SceneSphere&) const {
        float pdfW;
        const auto local = profile->sample(u_dir, pdfW);
        if (!local) return std::nullopt;
        const Vec3f d = frame.to_world(*local);
        return EmissionSample{position, d, d, scale * profile->candela(*local), 1.0f, 1.0f, pdfW};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f&, const Vec3f& dir, const SceneSphere&) const {
        return {1.0f, profile->pdf(frame.to_local(dir))};
    }
    float power(const SceneSphere&) const { return float(mean(scale) * profile->flux()); }
};

inline const PluginInfo& ies_plugin() {
    static const PluginInfo info{
        "emitter", "ies", "a point light with the intensity distribution of an IES (LM-63) photometric file",
        {{"filename", ParamType::String, "", "the .ies file (LM-63-1995 or -2002, type C), relative to the scene file"},
         {"intensity", ParamType::Rgb, "1", "scale: radiant intensity = intensity x candela / 683, W/sr"},
         {"to_world", ParamType::Transform, "", "placement (a rotation and a translation): the nadir along +z, horizontal angle 0 along +x"}},
        "Bilinear interpolation of the candela table; emission sampled by the profile (docs/lights.md)."};
    return info;
}

IesLight read_ies_light(Properties& p, const EmitterContext& ctx);

}  // namespace pathlab
