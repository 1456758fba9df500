// projector: Mitsuba 3's projection light (mitsuba3 src/emitters/projector.cpp), a pinhole camera
// run backwards. An image `irradiance` E(u, v) on the virtual image plane at z = 1 in front of
// the pinhole (in to_world's axes: z the axis, the image's u to -x and v to -y, as Mitsuba's
// perspective camera maps pixels) is projected into the scene: towards the local direction
// l = (x, y, z), z > 0,
//     u = 1/2 - x / (2 z tan(fov_x / 2)),   v = 1/2 - a y / (2 z tan(fov_x / 2))   (a = the image's width / height),
// and the radiant intensity is
//     I(l) = pi scale E(u, v) / cos^3(theta)   (cos theta = z / |l|; 0 outside the image),
// so that the irradiance it gives a plane facing it at distance 1 is pi scale E (Mitsuba's
// factor pi included). Power: the integral of I over directions, dw = cos^3(theta) dA on the
// plane z = 1: pi scale A mean(E), A the image's area on that plane.
//
// Incident sampling: the one direction towards the pinhole (delta position). Emission: a point
// of the image uniformly on the plane z = 1 (pdf 1 / (A cos^3 theta) per unit solid angle).
#pragma once

#include <cmath>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "core/frame.hpp"
#include "core/properties.hpp"
#include "lights/light_sample.hpp"
#include "lights/placement.hpp"
#include "textures/texture.hpp"

namespace pathlab {

struct ProjectorLight {
    Vec3f position;
    Frame axes;                            // to_world's x, y, z (z: the axis)
    float scale = 1;                       // Mitsuba's scale, times to_world's uniform scale squared
    std::shared_ptr<const Texture> irradiance;
    float tan_x = 1;                       // tan(fov_x / 2)
    float aspect = 1;                      // the image's width / height
    Rgb mean_irradiance{1.0f};             // E's mean over the image (the power's factor)

    static constexpr uint32_t flags = kLightDeltaPosition;

    // The image's area on the plane z = 1.
    float image_area() const { return (2 * tan_x) * (2 * tan_x / aspect); }
    // The half-angle of the cone about the axis that holds the image's corners.
    float half_angle() const { return std::atan(tan_x * std::sqrt(1 + 1 / (aspect * aspect))); }

    // I(w) towards the unit world direction w (0 outside the image).
    Rgb intensity(const Vec3f& w) const {
        const Vec3f l = axes.to_local(w);
        if (!(l.z > 0)) return Rgb(0.0f);
        const float u = 0.5f - l.x / (2 * l.z * tan_x), v = 0.5f - aspect * l.y / (2 * l.z * tan_x);
        if (!(u >= 0 && u <= 1 && v >= 0 && v <= 1)) return Rgb(0.0f);
        const float cos3 = l.z * l.z * l.z;
        return irradiance->eval(SurfaceUv(u, v)) * (kPi * scale / cos3);
    }

    std::optional<LightSample> sample_li(const Vec3f& p, Vec2f) const {
        const Vec3f d = position - p;
        const float dist2 = dot(d, d);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const Rgb I = intensity(-d / dist);
        if (is_black(I)) return std::nullopt;
        return LightSample{d / dist, dist, position, Vec3f(0.0f), I / dist2, 1.0f, true};
    }
    std::optional<EmissionSample> sample_emission(Vec2f, Vec2f u_dir, const SceneSphere&) const {
        const Vec3f l = normalize(Vec3f((1 - 2 * u_dir.x) * tan_x, (1 - 2 * u_dir.y) * tan_x / aspect, 1.0f));
        const Vec3f d = axes.to_world(l);
        const Rgb I = intensity(d);
        return EmissionSample{position, d, d, I, 1.0f, 1.0f, 1 / (image_area() * l.z * l.z * l.z)};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f&, const Vec3f& dir, const SceneSphere&) const {
        const Vec3f l = axes.to_local(dir);
        if (!(l.z > 0)) return {1.0f, 0.0f};
        const float x = l.x / l.z, y = l.y / l.z;
        if (!(std::abs(x) <= tan_x && std::abs(y) <= tan_x / aspect)) return {1.0f, 0.0f};
        return {1.0f, 1 / (image_area() * l.z * l.z * l.z)};
    }
    float power(const SceneSphere&) const { return kPi * scale * image_area() * mean(mean_irradiance); }
};

inline const PluginInfo& projector_plugin() {
    static const PluginInfo info{
        "emitter", "projector", "a projection light: an image thrown into the scene through a pinhole (Mitsuba 3's projector)",
        {{"irradiance", ParamType::Rgb, "1", "the image on the plane z = 1 (a texture, or a value); the irradiance it gives there is pi scale E", "", 0},
         {"scale", ParamType::Float, "1", "multiplies the irradiance"},
         {"fov", ParamType::Float, "", "field of view in degrees, along fov_axis (default: from focal_length)"},
         {"fov_axis", ParamType::String, "x", "the image axis fov spans: x, y, diagonal, smaller or larger"},
         {"focal_length", ParamType::String, "50mm", "a 35 mm film's lens, when fov is not given (the image's diagonal spans 43.27 mm)"},
         {"to_world", ParamType::Transform, "", "placement: at the origin, looking along +z (e.g. a lookat)", "toWorld"}}};
    return info;
}
// `irradiance`: a nested <texture name="irradiance"> (or a <ref> to one) the reader found, else none.
inline ProjectorLight read_projector_light(Properties& p, const EmitterContext& ctx) {
    ProjectorLight l;
    std::shared_ptr<const Texture> image = ctx.texture;
    if (p.has("irradiance")) {
        if (image) p.fail("irradiance", "a projector's irradiance is given twice");
        image = std::make_shared<const Texture>(ConstantTexture{p.get_rgb("irradiance")});
    }
    if (!image) image = std::make_shared<const Texture>(ConstantTexture{Rgb(1.0f)});
    if (min_component(image->min_value()) < 0) p.fail("irradiance", "a projector's irradiance must not be negative");
    // The image's aspect: a bitmap's resolution, 1 for a constant or a pattern (Mitsuba's
    // resolution() of a texture without pixels).
    const auto* bitmap = std::get_if<BitmapTexture>(&image->model());
    if (bitmap) l.aspect = float(bitmap->width()) / float(bitmap->height());
    // The field of view along x (mitsuba3 src/core/util.cpp parse_fov): fov along fov_axis, or a
    // focal length on a 36 x 24 mm film, whose diagonal it spans.
    double tan_axis, axis_over_x;
    const double a = l.aspect;
    if (p.has("fov")) {
        const double fov = p.get_float("fov");
        if (!(fov > 0 && fov < 180)) p.fail("fov", fmt::format("a projector's fov must be between 0 and 180 degrees, got {}", fov));
        tan_axis = std::tan(fov * kPi / 360);
        const std::string axis = p.get_string("fov_axis");
        if (axis == "x") axis_over_x = 1;
        else if (axis == "y") axis_over_x = 1 / a;
        else if (axis == "diagonal") axis_over_x = std::sqrt(1 + 1 / (a * a));
        else if (axis == "smaller") axis_over_x = a > 1 ? 1 / a : 1;
        else if (axis == "larger") axis_over_x = a > 1 ? 1 : 1 / a;
        else p.fail("fov_axis", fmt::format("unsupported fov_axis '{}'; supported: x, y, diagonal, smaller, larger", axis));
    } else {
        std::string f = p.get_string("focal_length");
        if (f.size() > 2 && f.compare(f.size() - 2, 2, "mm") == 0) f.resize(f.size() - 2);
        char* end = nullptr;
        const double mm = std::strtod(f.c_str(), &end);
        if (end == f.c_str() || *end != 0 || !(mm > 0 && mm < 1e6))
            p.fail("focal_length", fmt::format("focal_length must be a length in millimetres such as 50mm, got '{}'", p.get_string("focal_length")));
        tan_axis = std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2 * mm);
        axis_over_x = std::sqrt(1 + 1 / (a * a));
    }
    l.tan_x = float(tan_axis / axis_over_x);
    const float s = p.get_float("scale");
    if (!(s >= 0) || !std::isfinite(s)) p.fail("scale", fmt::format("a projector's scale must be finite and not negative, got {}", s));
    l.axes = rotation_frame(p, "projector");
    l.position = Vec3f(0.0f);
    double uniform_scale = 1;
    if (const auto t = p.get_transform("to_world")) {
        l.position = Vec3f(t->point(Vec3d(0.0)));
        uniform_scale = length(t->vector({0, 0, 1}));
    }
    // Mitsuba measures z in the projector's own (scaled) space: I scales with the square of to_world's scale.
    l.scale = float(s * uniform_scale * uniform_scale);
    l.irradiance = std::move(image);
    // The image's mean: its texels' for a bitmap (a midpoint rule at 4 x its resolution), the value for the rest.
    const int nx = bitmap ? 4 * bitmap->width() : 16, ny = bitmap ? 4 * bitmap->height() : 16;
    Vec3d sum(0.0);
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) sum += Vec3d(l.irradiance->eval(SurfaceUv((x + 0.5f) / float(nx), (y + 0.5f) / float(ny))));
    l.mean_irradiance = Rgb(sum / double(nx * ny));
    return l;
}

}  // namespace pathlab
