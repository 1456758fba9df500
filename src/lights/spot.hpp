// spot: a point light emitting into a cone (Mitsuba 3's spot emitter), at the origin of its
// frame and pointing along its +z axis (to_world, e.g. a lookat, places and aims it).
//
// XML (Mitsuba 3): intensity (rgb, default 1), cutoff_angle (degrees, default 20), beam_width
// (degrees, default 3/4 of cutoff_angle), to_world, and an optional projected `texture`.
//
// Falloff, Mitsuba 3's linear ramp in angle: the radiant intensity at angle theta from the axis
// is I * falloff(theta) with falloff = 1 for theta <= beam_width, (cutoff - theta) /
// (cutoff - beam_width) between them, 0 from cutoff_angle on. Power:
//   2 pi I [1 - (sin c - sin b) / (c - b)]  (c = cutoff, b = beam width; 2 pi I (1 - cos c) if b = c).
//
// Projected texture (Mitsuba 3): the intensity towards a unit direction (x, y, z) of the
// to_world's own axes is multiplied by the texture at
//   uv = 0.5 + 0.5 (x, y) / (z tan(cutoff_angle)),
// so the square [0, 1]^2 spans the cutoff cone's tangent plane; it needs cutoff_angle < 90.
//
// Incident sampling: the one direction towards the light, Le = I falloff / d^2 (delta).
// Emission: the light's position (delta position, pdfA = 1) and a direction uniformly inside the
// cutoff cone (pdfW = 1 / (2 pi (1 - cos c))), Le = I falloff.
#pragma once

#include <cmath>
#include <memory>
#include <optional>

#include "core/frame.hpp"
#include "core/properties.hpp"
#include "core/sampling.hpp"
#include "lights/light_sample.hpp"
#include "lights/placement.hpp"
#include "textures/texture.hpp"

namespace pathlab {

struct SpotLight {
    Vec3f position;
    Frame frame;  // frame.n: the axis
    Rgb intensity;
    float cutoff = 0, beam_width = 0;  // radians
    float cos_cutoff = 1, cos_beam_width = 1;
    // The projected texture (none: a uniform beam), the to_world's axes its uv follow (`frame`
    // above is any basis around the axis), tan(cutoff), and the texture's mean over the beam
    // weighted by the falloff (the power's factor).
    std::shared_ptr<const Texture> texture;
    Frame projection;
    float uv_factor = 0;
    Rgb texture_mean{1.0f};

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

    // The texture's factor towards the world direction w (inside the cutoff cone).
    Rgb projected(const Vec3f& w) const {
        const Vec3f l = projection.to_local(w);
        const float scale = 0.5f / (l.z * uv_factor);
        return texture->eval(Vec2f(0.5f + l.x * scale, 0.5f + l.y * scale));
    }
    void set_texture(std::shared_ptr<const Texture> t, const Frame& axes) {
        texture = std::move(t);
        projection = axes;
        uv_factor = std::tan(cutoff);
        // Midpoint rule over the cone, uniform in solid angle: the falloff-weighted mean.
        constexpr int n = 64;
        Vec3d sum(0.0);
        double weight = 0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const Vec3f local = square_to_uniform_cone(Vec2f((i + 0.5f) / n, (j + 0.5f) / n), cos_cutoff);
                const float f = falloff(local);
                sum += Vec3d(projected(frame.to_world(local))) * double(f);
                weight += f;
            }
        texture_mean = weight > 0 ? Rgb(sum / weight) : Rgb(0.0f);
    }

    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f) const {
        const Vec3f d = position - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const float f = falloff_world(-d / dist);
        if (f == 0) return std::nullopt;
        Rgb Li = intensity * (f / dist2);
        if (texture) Li *= projected(-d / dist);
        return LightSample{d / dist, dist, position, Vec3f(0.0f), Li, 1.0f, true};
    }
    std::optional<EmissionSample> sample_emission(Vec2f, Vec2f u_dir, const SceneSphere&) const {
        const Vec3f local = square_to_uniform_cone(u_dir, cos_cutoff);
        const Vec3f d = frame.to_world(local);
        Rgb Le = intensity * falloff(local);
        if (texture) Le *= projected(d);
        return EmissionSample{position, d, d, Le, 1.0f, 1.0f, uniform_cone_pdf(cos_cutoff)};
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
    float power(const SceneSphere&) const {
        return float(mean(texture ? intensity * texture_mean : intensity) * falloff_solid_angle());
    }
};

inline const PluginInfo& spot_plugin() {
    static const PluginInfo info{"emitter", "spot", "a spot light: a point light emitting into a cone, with a linear falloff",
                                 {{"intensity", ParamType::Rgb, "1", "radiant intensity I on the axis, W/sr"},
                                  {"cutoff_angle", ParamType::Float, "20", "degrees from the axis beyond which it is black", "cutoffAngle"},
                                  {"beam_width", ParamType::Float, "", "degrees from the axis of full intensity (default: 3/4 of cutoff_angle)", "beamWidth"},
                                  {"to_world", ParamType::Transform, "", "placement: at the origin, pointing along +z (e.g. a lookat)", "toWorld"},
                                  {"texture", ParamType::Rgb, "", "projected onto the beam, multiplies intensity: uv = 0.5 + 0.5 (x, y) / (z tan(cutoff_angle)) in to_world's axes; needs cutoff_angle < 90", "", 0}}};
    return info;
}
// `texture`: a nested <texture name="texture"> (or a <ref> to one) the reader found, else none.
inline SpotLight read_spot_light(Properties& p, const EmitterContext& ctx) {
    const float cutoff = p.get_float("cutoff_angle");
    if (!(cutoff > 0 && cutoff <= 180)) p.fail("cutoff_angle", "a spot's cutoff_angle must be in (0, 180] degrees");
    const float beam = p.has("beam_width") ? p.get_float("beam_width") : cutoff * 0.75f;
    if (!(beam >= 0 && beam <= cutoff)) p.fail("beam_width", "a spot's beam_width must be in [0, cutoff_angle] degrees");
    Vec3d position(0.0), axis(0, 0, 1);
    if (const auto t = p.get_transform("to_world")) position = t->point(position), axis = t->vector(axis);
    if (!(length(axis) > 0)) p.fail("to_world", "the to_world of a spot emitter turns its axis to nothing");
    SpotLight spot(Vec3f(position), Vec3f(normalize(axis)), p.get_rgb("intensity"), cutoff, beam);
    std::shared_ptr<const Texture> texture = ctx.texture;
    if (p.has("texture")) {
        if (texture) p.fail("texture", "a spot's texture is given twice");
        texture = std::make_shared<const Texture>(ConstantTexture{p.get_rgb("texture")});
    }
    if (texture) {
        if (!(cutoff < 90)) p.fail("cutoff_angle", "a spot's projected texture needs a cutoff_angle below 90 degrees");
        if (min_component(texture->min_value()) < 0) p.fail("texture", "a spot's texture must not be negative");
        spot.set_texture(std::move(texture), rotation_frame(p, "spot"));
    }
    return spot;
}

}  // namespace pathlab
