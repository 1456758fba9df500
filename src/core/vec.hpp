// Small fixed-size vectors. Vec3f doubles as an RGB colour (three independent linear channels).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace pathlab {

template <typename T>
struct Vec2 {
    T x{}, y{};
    constexpr Vec2() = default;
    constexpr Vec2(T x_, T y_) : x(x_), y(y_) {}
    constexpr T operator[](int i) const { return i == 0 ? x : y; }
    constexpr Vec2 operator+(const Vec2& o) const { return {x + o.x, y + o.y}; }
    constexpr Vec2 operator*(T s) const { return {x * s, y * s}; }
    constexpr bool operator==(const Vec2&) const = default;
};

template <typename T>
struct Vec3 {
    T x{}, y{}, z{};
    constexpr Vec3() = default;
    constexpr explicit Vec3(T v) : x(v), y(v), z(v) {}
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    template <typename U>
    constexpr explicit Vec3(const Vec3<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

    constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
    constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    constexpr Vec3& operator*=(const Vec3& o) { x *= o.x; y *= o.y; z *= o.z; return *this; }
    constexpr Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
    constexpr Vec3& operator/=(T s) { return *this *= T(1) / s; }
    constexpr bool operator==(const Vec3&) const = default;
};

template <typename T> constexpr Vec3<T> operator+(Vec3<T> a, const Vec3<T>& b) { return a += b; }
template <typename T> constexpr Vec3<T> operator-(Vec3<T> a, const Vec3<T>& b) { return a -= b; }
template <typename T> constexpr Vec3<T> operator*(Vec3<T> a, const Vec3<T>& b) { return a *= b; }
template <typename T> constexpr Vec3<T> operator*(Vec3<T> a, T s) { return a *= s; }
template <typename T> constexpr Vec3<T> operator*(T s, Vec3<T> a) { return a *= s; }
template <typename T> constexpr Vec3<T> operator/(Vec3<T> a, T s) { return a /= s; }
template <typename T> constexpr Vec3<T> operator/(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.x / b.x, a.y / b.y, a.z / b.z};
}

template <typename T> constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T> constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T> inline T length(const Vec3<T>& a) { return std::sqrt(dot(a, a)); }
template <typename T> inline Vec3<T> normalize(const Vec3<T>& a) { return a / length(a); }
template <typename T> constexpr T max_component(const Vec3<T>& a) { return std::max({a.x, a.y, a.z}); }
template <typename T> constexpr T min_component(const Vec3<T>& a) { return std::min({a.x, a.y, a.z}); }
template <typename T> constexpr T mean(const Vec3<T>& a) { return (a.x + a.y + a.z) / T(3); }
template <typename T> constexpr bool is_black(const Vec3<T>& a) { return a.x == 0 && a.y == 0 && a.z == 0; }
template <typename T> inline Vec3<T> abs(const Vec3<T>& a) { return {std::abs(a.x), std::abs(a.y), std::abs(a.z)}; }
template <typename T> inline Vec3<T> min(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <typename T> inline Vec3<T> max(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <typename T> inline bool is_finite(const Vec3<T>& a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
// Mirror reflection of w about the unit normal n (both pointing away from the surface).
template <typename T> constexpr Vec3<T> reflect(const Vec3<T>& w, const Vec3<T>& n) {
    return T(2) * dot(w, n) * n - w;
}

using Vec2f = Vec2<float>;
using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;
using Rgb = Vec3f;  // linear RGB radiance / reflectance

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInf = __builtin_huge_valf();

// Rec. 709 luminance of a linear RGB value.
inline constexpr float luminance(const Rgb& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace pathlab
