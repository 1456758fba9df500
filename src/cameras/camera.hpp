// Pinhole camera. Raster coordinates: x to the right, y down, pixel (i, j) covers
// [i, i+1) x [j, j+1), row 0 at the top. With u = 2 sx / W - 1 and v = 2 sy / H - 1 in [-1, 1],
//   direction = normalize(forward + tan_x u right - tan_y v up).
// The course camera uses tan_x = tan_y = tan(fov/2) at every resolution (each axis spans the
// field of view; pixels are non-square for non-square images). Scene-file cameras derive the
// other axis from the aspect ratio, keeping pixels square.
#pragma once

#include <cmath>

#include "core/vec.hpp"
#include "geometry/ray.hpp"

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
class CameraRays {
public:
    CameraRays(const Camera& cam, int width, int height) : cam_(cam), width_(float(width)), height_(float(height)) {
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

private:
    Camera cam_;
    float width_, height_;
    float tan_x_ = 1, tan_y_ = 1;
};

}  // namespace pathlab
