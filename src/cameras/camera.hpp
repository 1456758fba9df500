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
#include <vector>

#include "core/sampling.hpp"
#include "core/vec.hpp"
#include "geometry/ray.hpp"
#include "core/properties.hpp"

namespace pathlab {

enum class FovAxis { X, Y, Smaller, Larger, EachAxis, Diagonal };

// The sensor's projection: a pinhole (perspective), a thin lens (depth of field) or parallel
// rays (orthographic).
enum class CameraKind { Perspective, ThinLens, Orthographic };

struct Camera {
    Vec3f position{0, 0, 0};
    Vec3f forward{0, 1, 0}, right{1, 0, 0}, up{0, 0, 1};  // unit; right/up span the image plane
    float fov_degrees = 45;
    FovAxis fov_axis = FovAxis::EachAxis;
    // Scene-file sensors (Mitsuba's perspective, thinlens, orthographic; the defaults are the
    // course's pinhole, bit for bit):
    CameraKind kind = CameraKind::Perspective;
    float near_clip = 0, far_clip = kInf;  // depth range seen, along `forward`
    // The film's window that is rendered (hdrfilm's crop, as fractions of the full film) and
    // the principal point's offset from the film's centre (fractions of the film's size).
    float window_x0 = 0, window_y0 = 0, window_x1 = 1, window_y1 = 1;
    float principal_x = 0, principal_y = 0;
    float aperture_radius = 0, focus_distance = 1;  // thinlens
    float ortho_half_x = 1, ortho_half_y = 1;       // orthographic: half the view's width (and height at aspect 1), world units

    // True for the plain pinhole (no window, offset or clipping): ray generation as before.
    bool plain() const {
        return kind == CameraKind::Perspective && near_clip == 0 && far_clip == kInf && window_x0 == 0 && window_y0 == 0 &&
               window_x1 == 1 && window_y1 == 1 && principal_x == 0 && principal_y == 0;
    }

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

// A camera prepared for one image resolution. The pinhole's formulas above hold for a window
// of the film too (a crop, a principal point offset): the image plane is then the window's part
// of it, of area A = 4 tan_x tan_y (x1 - x0) (y1 - y0), and We and pdfW use that A. Thin lens
// and orthographic cameras generate rays (for the camera-side integrators) but are not
// connected to: integrators that connect to the camera refuse them (RenderJob).
class PerspectiveCamera {
public:
    PerspectiveCamera(const Camera& cam, int width, int height)
        : cam_(cam), width_(float(width)), height_(float(height)), plain_(cam.plain()) {
        const float t = std::tan(0.5f * cam.fov_degrees * kPi / 180.0f);
        wx_ = cam.window_x1 - cam.window_x0, wy_ = cam.window_y1 - cam.window_y0;
        // tan_x / tan_y for square pixels: the full film's aspect ratio.
        const float aspect = plain_ ? width_ / height_ : (width_ / wx_) / (height_ / wy_);
        if (cam.kind == CameraKind::Orthographic) {
            half_x_ = cam.ortho_half_x, half_y_ = cam.ortho_half_y / aspect;
            return;
        }
        bool along_x = true;
        switch (cam.fov_axis) {
            case FovAxis::EachAxis: tan_x_ = tan_y_ = t; return;
            case FovAxis::X: along_x = true; break;
            case FovAxis::Y: along_x = false; break;
            case FovAxis::Smaller: along_x = aspect <= 1; break;
            case FovAxis::Larger: along_x = aspect >= 1; break;
            case FovAxis::Diagonal: {
                const float diagonal = std::sqrt(aspect * aspect + 1);
                tan_x_ = t * aspect / diagonal, tan_y_ = t / diagonal;
                return;
            }
        }
        tan_x_ = along_x ? t : t * aspect;
        tan_y_ = along_x ? t / aspect : t;
    }
    Ray generate(float sx, float sy) const {
        if (!plain_) [[unlikely]]
            return generate(sx, sy, Vec2f(0.5f, 0.5f));
        const float u = 2.0f * sx / width_ - 1.0f, v = 2.0f * sy / height_ - 1.0f;
        const Vec3f d = cam_.forward + cam_.right * (tan_x_ * u) - cam_.up * (tan_y_ * v);
        return Ray{cam_.position, normalize(d), kInf};
    }
    // Any camera: `lens` is a uniform 2D sample of the aperture (used by thinlens only). Out of
    // line, so that the pinhole's generate() stays small where it is inlined (pt-mis's loop).
    [[gnu::noinline]] Ray generate(float sx, float sy, const Vec2f& lens) const {
        if (plain_) return generate(sx, sy);
        const float u = 2 * (cam_.window_x0 + wx_ * (sx / width_) + cam_.principal_x) - 1;
        const float v = 2 * (cam_.window_y0 + wy_ * (sy / height_) + cam_.principal_y) - 1;
        Vec3f o = cam_.position, d;
        if (cam_.kind == CameraKind::Orthographic) {
            o = o + cam_.right * (half_x_ * u) - cam_.up * (half_y_ * v);
            d = cam_.forward;
        } else {
            d = cam_.forward + cam_.right * (tan_x_ * u) - cam_.up * (tan_y_ * v);  // unit depth
            if (cam_.kind == CameraKind::ThinLens && cam_.aperture_radius > 0) {
                const Vec3f focus = o + d * cam_.focus_distance;
                const Vec2f l = square_to_concentric_disk(lens) * cam_.aperture_radius;
                o = o + cam_.right * l.x + cam_.up * l.y;
                d = focus - o;
            }
            d = normalize(d);
        }
        // The clipping planes, at depths near and far along `forward`.
        const float cos_theta = dot(d, cam_.forward);
        const float t_near = cam_.near_clip / cos_theta, t_far = cam_.far_clip / cos_theta;
        return Ray{o + d * t_near, d, t_far - t_near};
    }
    bool needs_lens_sample() const { return cam_.kind == CameraKind::ThinLens && cam_.aperture_radius > 0; }
    CameraKind kind() const { return cam_.kind; }

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
    // Area of the image plane (the window's part of it) at distance 1 from the pinhole.
    float image_plane_area() const { return plain_ ? 4 * tan_x_ * tan_y_ : 4 * tan_x_ * tan_y_ * wx_ * wy_; }

    // The raster position that the unit direction d (from the pinhole) passes through, if it
    // lies within the image.
    std::optional<Vec2f> raster_of(const Vec3f& d) const {
        const float z = dot(d, cam_.forward);
        if (!(z > 0)) return std::nullopt;
        const float u = dot(d, cam_.right) / (z * tan_x_), v = -dot(d, cam_.up) / (z * tan_y_);
        Vec2f r;
        if (plain_) [[likely]] {
            r = {(u + 1) * 0.5f * width_, (v + 1) * 0.5f * height_};
        } else {
            r = {((u + 1) * 0.5f - cam_.principal_x - cam_.window_x0) / wx_ * width_,
                 ((v + 1) * 0.5f - cam_.principal_y - cam_.window_y0) / wy_ * height_};
        }
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
        if (!plain_) {
            const float depth = -dot(to_camera, cam_.forward);
            if (!(depth >= cam_.near_clip && depth <= cam_.far_clip)) return std::nullopt;
        }
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
    bool plain_ = true;
    float tan_x_ = 1, tan_y_ = 1;
    float wx_ = 1, wy_ = 1;          // the window's size, as fractions of the film
    float half_x_ = 1, half_y_ = 1;  // orthographic: half the view's extent along right and up
};

// The scene-file sensors (the reader, read_sensor.cpp, turns to_world into the camera).
inline std::vector<ParamInfo> projective_sensor_params() {
    return {{"fov", ParamType::Float, "", "field of view in degrees (default: from focal_length)"},
            {"fov_axis", ParamType::String, "x",
             "the axis fov spans: x, y, diagonal, smaller, larger, or pathlab's each (both axes span fov, as the course's camera)",
             "fovAxis"},
            {"focal_length", ParamType::String, "50mm",
             "instead of fov: a 35 mm film's (36 x 24 mm) focal length (\"50mm\" or 50); the field of view along the film's "
             "diagonal is 2 atan(sqrt(36^2 + 24^2) / (2 f)), as Mitsuba 3 and 0.6 (46.8 degrees for 50 mm: 34.0 along x on a square film)",
             "focalLength"},
            {"to_world", ParamType::Transform, "", "placement (usually a lookat); Mitsuba's camera looks along +z, +y up, +x left", "toWorld"},
            {"near_clip", ParamType::Float, "",
             "nothing nearer (depth along the view) is seen; Mitsuba's default 0.01 is not applied unless given (the course's images stay the same)",
             "nearClip"},
            {"far_clip", ParamType::Float, "", "nothing farther is seen (Mitsuba's default 1e4 is not applied unless given)", "farClip"},
            {"principal_point_offset_x", ParamType::Float, "0", "the principal point's offset from the film's centre, a fraction of its width"},
            {"principal_point_offset_y", ParamType::Float, "0", "... of its height"},
            {"shutter_open", ParamType::Float, "0", "accepted and ignored: nothing moves in a pathlab scene", "shutterOpen"},
            {"shutter_close", ParamType::Float, "0", "accepted and ignored: nothing moves in a pathlab scene", "shutterClose"}};
}
inline const PluginInfo& perspective_plugin() {
    static const PluginInfo info{"sensor", "perspective", "a pinhole camera", projective_sensor_params()};
    return info;
}
inline const PluginInfo& thinlens_plugin() {
    static const PluginInfo info = [] {
        PluginInfo i{"sensor", "thinlens", "a thin lens camera: depth of field (camera-side integrators only; lt, bdpt, vcm, bpm, sppm, ppm and ic refuse it)",
                     projective_sensor_params()};
        i.params.push_back({"aperture_radius", ParamType::Float, "", "the lens's radius (required), scene units", "apertureRadius"});
        i.params.push_back({"focus_distance", ParamType::Float, "", "the distance in focus (required), scene units", "focusDistance"});
        return i;
    }();
    return info;
}
inline const PluginInfo& orthographic_plugin() {
    static const PluginInfo info{"sensor", "orthographic",
                                 "parallel rays along the view: [-1, 1] of camera space across the film, scaled by to_world (camera-side integrators only)",
                                 {{"to_world", ParamType::Transform, "", "placement and size: its scale sets the view's extent", "toWorld"},
                                  {"near_clip", ParamType::Float, "", "nothing nearer is seen (not applied unless given)", "nearClip"},
                                  {"far_clip", ParamType::Float, "", "nothing farther is seen (not applied unless given)", "farClip"},
                                  {"shutter_open", ParamType::Float, "0", "accepted and ignored", "shutterOpen"},
                                  {"shutter_close", ParamType::Float, "0", "accepted and ignored", "shutterClose"}}};
    return info;
}

}  // namespace pathlab
