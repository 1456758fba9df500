// envmap: an environment map, radiance arriving from every direction as a latitude-longitude
// image shows it (rays that escape the scene see it). docs/lights.md has the pictures.
//
// XML (Mitsuba 3): filename (.exr, .hdr or .pfm), scale (float, default 1), to_world (a rotation).
//
// Mapping, Mitsuba 3's convention, in the emitter's frame (to_world turns it): a direction d has
// theta = acos(d.y) and phi = atan2(d.x, -d.z) in [0, 2 pi), and lies at u = phi / (2 pi),
// v = theta / pi of the image: the top row looks up (+y), the left edge towards -z, a quarter of
// the way across towards +x, the middle towards +z. Texel (x, y) of a W x H image sits at
// u = (x + 1/2) / W (texel-centred) and v = y / (H - 1) (the first row at the zenith, the last at
// the nadir), as Mitsuba 3 looks it up (envmap.cpp, eval_spectrum); for sampling, its cell is
// [x/W, (x+1)/W) x [y/H, (y+1)/H).
//
// Lookup: bilinear between the four nearest texels, wrapping around in u.
//
// Sampling (incident and emitted directions alike): a piecewise-constant 2D distribution over
// the texels' cells of [0, 1)^2 (core/distribution.hpp), with the value of texel (x, y)
//     f = (the largest luminance the bilinear lookup takes in the texel's cell)
//       x (the largest sin(theta) over the texel's row),
// i.e. the cell maxima of the integrand luminance(L) sin(theta): the bilinear function is
// largest at a corner of one of its patches inside the cell, so the maximum is that of at most
// 9 values (the cell's edges and the texel's centre in u, by the cell's edges and the image row
// between them in v). Every direction where the lookup
// is non-zero has a non-zero density, and a sample's luminance weight L / pdfW never exceeds
// 2 pi^2 mean(f). A point (u, v) of the distribution is the direction above; its density per
// unit solid angle is pdf_uv / (2 pi^2 sin(theta)) (dphi dtheta = 2 pi^2 du dv, dw = sin(theta)
// dtheta dphi), converted in one place, uv_density_to_solid_angle. Directions at the poles
// (sin(theta) = 0) are never sampled and have density 0.
//
// Emission (light paths): a direction sampled as above (the light travels the other way) from
// a point uniformly on the disk of the scene's bounding radius R perpendicular to it, R before
// the scene's centre (pdfA = 1 / (pi R^2)), as the constant environment does (constant.hpp), so
// that bdpt's densities at infinity (a direction's solid-angle density, the entry disk's area
// density) are the same for both. Power: pi R^2 * pi * (the solid-angle mean of the map's mean
// channel), as for a constant environment of that radiance.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "core/distribution.hpp"
#include "core/frame.hpp"
#include "core/properties.hpp"
#include "lights/constant.hpp"
#include "lights/light_sample.hpp"
#include "lights/placement.hpp"

namespace pathlab {

// The image, its sampling distribution and its orientation; immutable, shared by the copies of
// the light.
class EnvMap {
public:
    // texels: width x height linear RGB values (top row first, already scaled), finite and >= 0.
    // to_world: the emitter frame's x, y and z axes in world space (orthonormal).
    EnvMap(int width, int height, std::vector<Rgb> texels, const Frame& to_world = Frame());

    int width() const { return width_; }
    int height() const { return height_; }
    const Rgb& texel(int x, int y) const { return texels_[size_t(y) * size_t(width_) + size_t(x)]; }
    const Frame& frame() const { return frame_; }
    const Distribution2D& distribution() const { return distribution_; }

    // Bilinear lookup at image coordinates uv (u wraps around, v is clamped).
    Rgb lookup(Vec2f uv) const;
    // The emitter-frame direction at uv, and back (u and v in [0, 1)).
    static Vec3f uv_to_direction(Vec2f uv);
    static Vec2f direction_to_uv(const Vec3f& local);
    // The texel whose cell holds the world direction w (unit).
    std::pair<int, int> texel_of(const Vec3f& w) const;
    // A density per unit area of [0, 1)^2 as a density per unit solid angle.
    static float uv_density_to_solid_angle(float pdf_uv, float sin_theta) {
        return sin_theta > 0 ? pdf_uv / (2 * kPi * kPi * sin_theta) : 0.0f;
    }

    // Radiance arriving from the world direction w (towards the environment, any length).
    Rgb Le(const Vec3f& w) const { return lookup(direction_to_uv(frame_.to_local(normalize(w)))); }

    struct Sample {
        Vec3f wi;   // world direction towards the environment
        Vec2f uv;
        Rgb Le;
        float pdfW = 0;
        int x = 0, y = 0;  // the texel cell the distribution chose
    };
    std::optional<Sample> sample(Vec2f u) const;
    // The solid-angle density with which sample() produces the world direction w.
    float pdf(const Vec3f& w) const;
    // The solid-angle mean of mean(L) over the sphere (the radiance of a constant environment
    // of the same power).
    float mean_radiance() const { return mean_radiance_; }

private:
    int width_, height_;
    std::vector<Rgb> texels_;
    Frame frame_;
    Distribution2D distribution_;
    float mean_radiance_ = 0;
};

struct EnvMapLight {
    std::shared_ptr<const EnvMap> map;

    static constexpr uint32_t flags = kLightInfinite;

    std::optional<LightSample> sample_li(const Vec3f&, Vec2f u) const {
        const auto s = map->sample(u);
        if (!s) return std::nullopt;
        return LightSample{s->wi, kInf, Vec3f(0.0f), Vec3f(0.0f), s->Le, s->pdfW, false};
    }
    // Solid-angle density with which sample_li produces the direction w (towards the environment).
    float pdf_li(const Vec3f& w) const { return map->pdf(w); }
    // Radiance arriving along a ray that escapes in direction w.
    Rgb Le(const Vec3f& w) const { return map->Le(w); }
    std::optional<EmissionSample> sample_emission(Vec2f u_pos, Vec2f u_dir, const SceneSphere& s) const {
        const auto e = map->sample(u_dir);
        if (!e) return std::nullopt;
        const Vec3f d = -e->wi;
        return EmissionSample{point_on_entry_disk(s, d, u_pos), d, d, e->Le, 1.0f, entry_disk_pdfA(s), e->pdfW};
    }
    EmissionPdf pdf_emission(const Vec3f&, const Vec3f&, const Vec3f& dir, const SceneSphere& s) const {
        return {entry_disk_pdfA(s), map->pdf(-dir)};
    }
    float power(const SceneSphere& s) const { return kPi * s.radius * s.radius * kPi * map->mean_radiance(); }
};

const PluginInfo& envmap_plugin();
EnvMapLight read_envmap_light(Properties& p, const EmitterContext& ctx);

}  // namespace pathlab
