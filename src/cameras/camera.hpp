// Pinhole camera. Raster coordinates: x to the right, y down, pixel (i, j) covers
// [i, i+1) x [j, j+1), row 0 at the top. With u = 2 sx / W - 1 and v = 2 sy / H - 1 in [-1, 1],
//   direction = normalize(forward + tan_x u right - tan_y v up).
//
// Importance (for light paths that connect to the camera, Veach's We): the image plane at
// distance 1 has area A = 4 tan_x tan_y, and a ray leaving the pinhole in the unit direction d
// at angle theta to `forward` carries
//   We(d) = 1 / (A cos^4 theta)   inside the image, 0 outside,
// so that the integral of We cos theta over the image's directions is 1 (d omega =
// cos^3 theta dA on the plane). A pixel's value is then the image-wide measurement times the
// pixel count, which is what a light tracer's splats add up to when every pass traces one
// light path per pixel. Rays generated from uniformly distributed raster positions have the
// solid-angle density pdfW(d) = 1 / (A cos^3 theta); the pinhole's position is a delta
// (pdfA = 1).
// The course camera uses tan_x = tan_y = tan(fov/2) at every resolution (each axis spans the
// field of view; pixels are non-square for non-square images). Scene-file cameras derive the
// other axis from the aspect ratio, keeping pixels square.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>

#include "core/vec.hpp"
#include "geometry/ray.hpp"
#include "core/properties.hpp"

namespace pathlab {

enum class FovAxis { X, Y, Smaller, Larger, EachAxis };

struct Camera {
    Vec3f position{0, 0, 0};
    Vec3f forward{0, 1, 0}, right{1, 0, 0}, up{0, 0, 1};  // unit; right/up span the image plane
    float fov_degrees = 45;
    FovAxis fov_axis = FovAxis::EachAxis;

    // Looks from `origin` towards `target` (forward = normalize(target - origin)).
    static Camera look_at(const Vec3f& origin, const Vec3f& target, const Vec3f& up_hint, float fov_degrees, FovAxis axis) {
        return look_along(origin, target - origin, up_hint, fov_degrees, axis);
    }
    // Builds right = normalize(forward x up_hint), up = right x forward.
    static Camera look_along(const Vec3f& position, const Vec3f& forward, const Vec3f& up_hint, float fov_degrees,
                             FovAxis axis) {
        Camera c;
        c.position = position;
        c.forward = normalize(forward);
        c.right = normalize(cross(c.forward, up_hint));
        c.up = cross(c.right, c.forward);
        c.fov_degrees = fov_degrees;
        c.fov_axis = axis;
        return c;
    }
};

// A camera prepared for one image resolution.
class PerspectiveCamera {
public:
    PerspectiveCamera(const Camera& cam, int width, int height) : cam_(cam), width_(float(width)), height_(float(height)) {
        const float t = std::tan(0.5f * cam.fov_degrees * kPi / 180.0f);
        const float aspect = width_ / height_;  // tan_x / tan_y for square pixels
        bool along_x = true;
        switch (cam.fov_axis) {
            case FovAxis::EachAxis: tan_x_ = tan_y_ = t; return;
            case FovAxis::X: along_x = true; break;
            case FovAxis::Y: along_x = false; break;
            case FovAxis::Smaller: along_x = width_ <= height_; break;
            case FovAxis::Larger: along_x = width_ >= height_; break;
        }
        tan_x_ = along_x ? t : t * aspect;
        tan_y_ = along_x ? t / aspect : t;
    }
    Ray generate(float sx, float sy) const {
        const float u = 2.0f * sx / width_ - 1.0f, v = 2.0f * sy / height_ - 1.0f;
        const Vec3f d = cam_.forward + cam_.right * (tan_x_ * u) - cam_.up * (tan_y_ * v);
        return Ray{cam_.position, normalize(d), kInf};
    }

    const Vec3f& position() const { return cam_.position; }
    // The angle between the rays through the image's centre and one pixel to its right: a
    // pixel's angular width (the photon methods' and the irradiance cache's radii scale with it).
    float pixel_angle() const {
        const float cx = 0.5f * width_, cy = 0.5f * height_;
        const Vec3f a = normalize(generate(cx, cy).d), b = normalize(generate(cx + 1, cy).d);
        return 2 * std::asin(std::min(1.0f, 0.5f * length(a - b)));
    }
    const Vec3f& forward() const { return cam_.forward; }
    int width() const { return int(width_); }
    int height() const { return int(height_); }
    // Area of the image plane at distance 1 from the pinhole.
    float image_plane_area() const { return 4 * tan_x_ * tan_y_; }

    // The raster position that the unit direction d (from the pinhole) passes through, if it
    // lies within the image.
    std::optional<Vec2f> raster_of(const Vec3f& d) const {
        const float z = dot(d, cam_.forward);
        if (!(z > 0)) return std::nullopt;
        const float u = dot(d, cam_.right) / (z * tan_x_), v = -dot(d, cam_.up) / (z * tan_y_);
        const Vec2f r{(u + 1) * 0.5f * width_, (v + 1) * 0.5f * height_};
        if (!(r.x >= 0 && r.x < width_ && r.y >= 0 && r.y < height_)) return std::nullopt;
        return r;
    }
    // The pixel (row-major index) of a raster position within the image.
    size_t pixel_of(const Vec2f& r) const {
        const size_t x = std::min(size_t(r.x), size_t(width_) - 1), y = std::min(size_t(r.y), size_t(height_) - 1);
        return y * size_t(width_) + x;
    }
    // Importance of the ray from the pinhole in the unit direction d (0 outside the image).
    float We(const Vec3f& d) const {
        if (!raster_of(d)) return 0.0f;
        const float c = dot(d, cam_.forward), c2 = c * c;
        return 1 / (image_plane_area() * c2 * c2);
    }
    // Solid-angle density of the direction of generate() at a uniformly random raster position.
    float pdf_direction(const Vec3f& d) const {
        if (!raster_of(d)) return 0.0f;
        const float c = dot(d, cam_.forward);
        return 1 / (image_plane_area() * c * c * c);
    }

    // Connects the scene point p to the lens: the direction towards the pinhole, the raster
    // position, the importance We, and the density of that direction as seen from p
    // (pdfW = d^2 / cos at the lens for the pinhole's delta position). A light path's vertex
    // at p then contributes beta f |cos at p| We / pdfW to the pixel.
    struct Connection {
        Vec3f wi;  // unit direction from p towards the camera
        float distance = 0;
        Vec2f raster;
        float We = 0, pdfW = 0;
    };
    std::optional<Connection> connect(const Vec3f& p) const {
        const Vec3f to_camera = cam_.position - p;
        const float dist2 = dot(to_camera, to_camera);
        if (!(dist2 > 0)) return std::nullopt;
        const float dist = std::sqrt(dist2);
        const Vec3f wi = to_camera / dist;
        const auto raster = raster_of(-wi);
        if (!raster) return std::nullopt;
        const float cos_lens = dot(-wi, cam_.forward);
        return Connection{wi, dist, *raster, We(-wi), dist2 / cos_lens};
    }

private:
    Camera cam_;
    float width_, height_;
    float tan_x_ = 1, tan_y_ = 1;
};

// The scene-file sensor (Mitsuba 3's perspective; the reader turns to_world into the camera).
inline const PluginInfo& perspective_plugin() {
    static const PluginInfo info{
        "sensor", "perspective", "a pinhole camera",
        {{"fov", ParamType::Float, "39.3077", "field of view in degrees"},
         {"fov_axis", ParamType::String, "x",
          "the axis fov spans: x, y, smaller, larger, or pathlab's each (both axes span fov, as the course's camera)"},
         {"to_world", ParamType::Transform, "", "placement (usually a lookat); Mitsuba's camera looks along +z, +y up, +x left"}}};
    return info;
}

}  // namespace pathlab
