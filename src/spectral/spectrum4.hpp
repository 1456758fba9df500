// A spectral quantity at the path's four wavelengths (SampledWavelengths): one float per lane,
// element-wise arithmetic, and the reductions a path tracer needs (average, max, is_black).
// Lane i always belongs to wavelength i of the path's SampledWavelengths; a lane whose
// wavelength was terminated (pdf 0) still carries a value, which the film then ignores.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace pathlab {

inline constexpr int kSpectrumLanes = 4;

struct Spectrum4 {
    std::array<float, kSpectrumLanes> v{};

    constexpr Spectrum4() = default;
    constexpr explicit Spectrum4(float c) : v{c, c, c, c} {}
    constexpr Spectrum4(float a, float b, float c, float d) : v{a, b, c, d} {}

    constexpr float& operator[](int i) { return v[size_t(i)]; }
    constexpr float operator[](int i) const { return v[size_t(i)]; }

#define PATHLAB_SPECTRUM4_OP(op)                                                         \
    constexpr Spectrum4& operator op##=(const Spectrum4& o) {                            \
        for (int i = 0; i < kSpectrumLanes; ++i) v[size_t(i)] op## = o.v[size_t(i)];    \
        return *this;                                                                    \
    }                                                                                    \
    constexpr Spectrum4& operator op##=(float s) {                                       \
        for (int i = 0; i < kSpectrumLanes; ++i) v[size_t(i)] op## = s;                  \
        return *this;                                                                    \
    }                                                                                    \
    friend constexpr Spectrum4 operator op(Spectrum4 a, const Spectrum4& b) { return a op## = b; } \
    friend constexpr Spectrum4 operator op(Spectrum4 a, float s) { return a op## = s; }
    PATHLAB_SPECTRUM4_OP(+)
    PATHLAB_SPECTRUM4_OP(-)
    PATHLAB_SPECTRUM4_OP(*)
    PATHLAB_SPECTRUM4_OP(/)
#undef PATHLAB_SPECTRUM4_OP

    friend constexpr Spectrum4 operator*(float s, Spectrum4 a) { return a *= s; }
    friend constexpr Spectrum4 operator-(Spectrum4 a) {
        for (float& x : a.v) x = -x;
        return a;
    }
    friend constexpr bool operator==(const Spectrum4&, const Spectrum4&) = default;

    constexpr float average() const { return (v[0] + v[1] + v[2] + v[3]) * 0.25f; }
    constexpr float max_value() const { return std::max(std::max(v[0], v[1]), std::max(v[2], v[3])); }
    constexpr float min_value() const { return std::min(std::min(v[0], v[1]), std::min(v[2], v[3])); }
    constexpr bool is_black() const { return v[0] == 0 && v[1] == 0 && v[2] == 0 && v[3] == 0; }
    bool is_finite() const {
        return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) && std::isfinite(v[3]);
    }
};

// The free functions RGB colours have (core/vec.hpp), so that code written once for both reads alike.
constexpr bool is_black(const Spectrum4& s) { return s.is_black(); }
inline bool is_finite(const Spectrum4& s) { return s.is_finite(); }
constexpr float max_component(const Spectrum4& s) { return s.max_value(); }

// a / b with 0 where b is 0 (a pdf lane of a terminated wavelength).
constexpr Spectrum4 safe_div(Spectrum4 a, const Spectrum4& b) {
    for (int i = 0; i < kSpectrumLanes; ++i) a[i] = b[i] != 0 ? a[i] / b[i] : 0.0f;
    return a;
}
inline Spectrum4 exp(Spectrum4 a) {
    for (float& x : a.v) x = std::exp(x);
    return a;
}
inline Spectrum4 sqrt(Spectrum4 a) {
    for (float& x : a.v) x = std::sqrt(x);
    return a;
}
constexpr Spectrum4 clamp(Spectrum4 a, float lo, float hi) {
    for (float& x : a.v) x = std::clamp(x, lo, hi);
    return a;
}
constexpr Spectrum4 max(Spectrum4 a, const Spectrum4& b) {
    for (int i = 0; i < kSpectrumLanes; ++i) a[i] = std::max(a[i], b[i]);
    return a;
}

}  // namespace pathlab
