// Affine transforms as 4x4 matrices in double precision (scene-file `to_world`). Composition
// follows Mitsuba: in a <transform> block each element is applied after the ones before it,
// so the block's matrix is M = T_last * ... * T_first.
#pragma once

#include <array>
#include <cmath>
#include <optional>

#include "core/vec.hpp"

namespace pathlab {

struct Transform {
    std::array<std::array<double, 4>, 4> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};

    static Transform translate(const Vec3d& t) {
        Transform r;
        r.m[0][3] = t.x, r.m[1][3] = t.y, r.m[2][3] = t.z;
        return r;
    }
    static Transform scale(const Vec3d& s) {
        Transform r;
        r.m[0][0] = s.x, r.m[1][1] = s.y, r.m[2][2] = s.z;
        return r;
    }
    // Right-handed rotation by `degrees` about `axis` (Rodrigues' formula).
    static Transform rotate(const Vec3d& axis, double degrees) {
        const Vec3d a = normalize(axis);
        const double rad = degrees * 3.14159265358979323846 / 180.0;
        const double c = std::cos(rad), s = std::sin(rad), t = 1 - c;
        Transform r;
        r.m[0] = {t * a.x * a.x + c, t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y, 0};
        r.m[1] = {t * a.x * a.y + s * a.z, t * a.y * a.y + c, t * a.y * a.z - s * a.x, 0};
        r.m[2] = {t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, t * a.z * a.z + c, 0};
        return r;
    }
    // Mitsuba's look-at: camera space has +z towards the target, +y up and +x to the left, so
    // the columns are (left, up', dir, origin) with left = normalize(up x dir).
    // Returns nothing when origin == target or up is parallel to the viewing direction.
    static std::optional<Transform> look_at(const Vec3d& origin, const Vec3d& target, const Vec3d& up) {
        const Vec3d d = target - origin;
        if (!(length(d) > 0)) return std::nullopt;
        const Vec3d dir = normalize(d);
        const Vec3d l = cross(up, dir);
        if (!(length(l) > 1e-12 * length(up))) return std::nullopt;
        const Vec3d left = normalize(l);
        const Vec3d new_up = cross(dir, left);
        Transform r;
        for (int i = 0; i < 3; ++i) {
            r.m[i][0] = left[i];
            r.m[i][1] = new_up[i];
            r.m[i][2] = dir[i];
            r.m[i][3] = origin[i];
        }
        return r;
    }

    Transform operator*(const Transform& b) const {
        Transform r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                double s = 0;
                for (int k = 0; k < 4; ++k) s += m[i][k] * b.m[k][j];
                r.m[i][j] = s;
            }
        return r;
    }

    Vec3d point(const Vec3d& p) const {
        Vec3d r;
        for (int i = 0; i < 3; ++i) r[i] = m[i][0] * p.x + m[i][1] * p.y + m[i][2] * p.z + m[i][3];
        return r;
    }
    Vec3d vector(const Vec3d& v) const {
        Vec3d r;
        for (int i = 0; i < 3; ++i) r[i] = m[i][0] * v.x + m[i][1] * v.y + m[i][2] * v.z;
        return r;
    }
    // Normals transform by the inverse transpose of the linear part: the cofactor matrix, which
    // is that times the determinant (a positive or negative scale, removed by normalising).
    Vec3d normal(const Vec3d& n) const {
        const auto& a = m;
        const double c[3][3] = {
            {a[1][1] * a[2][2] - a[1][2] * a[2][1], a[1][2] * a[2][0] - a[1][0] * a[2][2], a[1][0] * a[2][1] - a[1][1] * a[2][0]},
            {a[0][2] * a[2][1] - a[0][1] * a[2][2], a[0][0] * a[2][2] - a[0][2] * a[2][0], a[0][1] * a[2][0] - a[0][0] * a[2][1]},
            {a[0][1] * a[1][2] - a[0][2] * a[1][1], a[0][2] * a[1][0] - a[0][0] * a[1][2], a[0][0] * a[1][1] - a[0][1] * a[1][0]},
        };
        Vec3d r;
        for (int i = 0; i < 3; ++i) r[i] = c[i][0] * n.x + c[i][1] * n.y + c[i][2] * n.z;
        return determinant() < 0 ? -r : r;
    }
    double determinant() const {
        const auto& a = m;
        return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    }
    bool is_finite() const {
        for (const auto& row : m)
            for (double v : row)
                if (!std::isfinite(v)) return false;
        return true;
    }
    // The inverse of an affine, invertible transform (is_affine_invertible()).
    Transform inverse_affine() const {
        const double det = determinant();
        Transform r;
        // The linear part's inverse is its adjugate over the determinant; then the translation.
        const auto& a = m;
        r.m[0] = {a[1][1] * a[2][2] - a[1][2] * a[2][1], a[0][2] * a[2][1] - a[0][1] * a[2][2], a[0][1] * a[1][2] - a[0][2] * a[1][1], 0};
        r.m[1] = {a[1][2] * a[2][0] - a[1][0] * a[2][2], a[0][0] * a[2][2] - a[0][2] * a[2][0], a[0][2] * a[1][0] - a[0][0] * a[1][2], 0};
        r.m[2] = {a[1][0] * a[2][1] - a[1][1] * a[2][0], a[0][1] * a[2][0] - a[0][0] * a[2][1], a[0][0] * a[1][1] - a[0][1] * a[1][0], 0};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) r.m[size_t(i)][size_t(j)] /= det;
        for (int i = 0; i < 3; ++i)
            r.m[size_t(i)][3] = -(r.m[size_t(i)][0] * a[0][3] + r.m[size_t(i)][1] * a[1][3] + r.m[size_t(i)][2] * a[2][3]);
        return r;
    }
    // Affine (last row 0 0 0 1) and invertible.
    bool is_affine_invertible() const {
        return m[3][0] == 0 && m[3][1] == 0 && m[3][2] == 0 && m[3][3] == 1 && std::abs(determinant()) > 1e-300;
    }
};

}  // namespace pathlab
