// Four floats computed side by side: SSE2 on x86-64 (every x86-64 has it), four scalar lanes
// elsewhere. Only the operations whose results IEEE 754 fixes (+ - * /, sqrt, min, max,
// comparisons), so a lane gives the same float as the scalar expression written in the same order.
#pragma once

#if defined(__SSE2__)
#include <emmintrin.h>
#else
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#endif

namespace pathlab {

#if defined(__SSE2__)

struct Float4 {
    __m128 v;
    Float4() : v(_mm_setzero_ps()) {}
    explicit Float4(__m128 x) : v(x) {}
    Float4(float x) : v(_mm_set1_ps(x)) {}  // NOLINT: a scalar in every lane
    static Float4 load(const float* p) { return Float4(_mm_loadu_ps(p)); }
    void store(float* p) const { _mm_storeu_ps(p, v); }
};
// A comparison's result: all bits set in a lane where it holds.
struct Mask4 {
    __m128 v;
};

inline Float4 operator+(Float4 a, Float4 b) { return Float4(_mm_add_ps(a.v, b.v)); }
inline Float4 operator-(Float4 a, Float4 b) { return Float4(_mm_sub_ps(a.v, b.v)); }
inline Float4 operator*(Float4 a, Float4 b) { return Float4(_mm_mul_ps(a.v, b.v)); }
inline Float4 operator/(Float4 a, Float4 b) { return Float4(_mm_div_ps(a.v, b.v)); }
inline Float4 sqrt(Float4 a) { return Float4(_mm_sqrt_ps(a.v)); }
// min(a, b) = a < b ? a : b and max(a, b) = a > b ? a : b per lane.
inline Float4 min(Float4 a, Float4 b) { return Float4(_mm_min_ps(a.v, b.v)); }
inline Float4 max(Float4 a, Float4 b) { return Float4(_mm_max_ps(a.v, b.v)); }
inline Float4 abs(Float4 a) { return Float4(_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)); }
inline Mask4 operator<(Float4 a, Float4 b) { return {_mm_cmplt_ps(a.v, b.v)}; }
inline Mask4 operator<=(Float4 a, Float4 b) { return {_mm_cmple_ps(a.v, b.v)}; }
inline Mask4 operator>(Float4 a, Float4 b) { return {_mm_cmpgt_ps(a.v, b.v)}; }
inline Mask4 operator&(Mask4 a, Mask4 b) { return {_mm_and_ps(a.v, b.v)}; }
inline Mask4 operator|(Mask4 a, Mask4 b) { return {_mm_or_ps(a.v, b.v)}; }
// m ? a : b per lane.
inline Float4 select(Mask4 m, Float4 a, Float4 b) { return Float4(_mm_or_ps(_mm_and_ps(m.v, a.v), _mm_andnot_ps(m.v, b.v))); }

#else

struct Float4 {
    float v[4];
    Float4() : v{0, 0, 0, 0} {}
    Float4(float x) : v{x, x, x, x} {}  // NOLINT: a scalar in every lane
    static Float4 load(const float* p) {
        Float4 r;
        std::memcpy(r.v, p, sizeof r.v);
        return r;
    }
    void store(float* p) const { std::memcpy(p, v, sizeof v); }
};
struct Mask4 {
    bool v[4];
};

template <typename F> inline Float4 lanes4(F f) {
    Float4 r;
    for (int k = 0; k < 4; ++k) r.v[k] = f(k);
    return r;
}
template <typename F> inline Mask4 masks4(F f) {
    Mask4 r;
    for (int k = 0; k < 4; ++k) r.v[k] = f(k);
    return r;
}
inline Float4 operator+(Float4 a, Float4 b) { return lanes4([&](int k) { return a.v[k] + b.v[k]; }); }
inline Float4 operator-(Float4 a, Float4 b) { return lanes4([&](int k) { return a.v[k] - b.v[k]; }); }
inline Float4 operator*(Float4 a, Float4 b) { return lanes4([&](int k) { return a.v[k] * b.v[k]; }); }
inline Float4 operator/(Float4 a, Float4 b) { return lanes4([&](int k) { return a.v[k] / b.v[k]; }); }
inline Float4 sqrt(Float4 a) { return lanes4([&](int k) { return std::sqrt(a.v[k]); }); }
inline Float4 min(Float4 a, Float4 b) { return lanes4([&](int k) { return a.v[k] < b.v[k] ? a.v[k] : b.v[k]; }); }
inline Float4 max(Float4 a, Float4 b) { return lanes4([&](int k) { return a.v[k] > b.v[k] ? a.v[k] : b.v[k]; }); }
inline Float4 abs(Float4 a) { return lanes4([&](int k) { return std::abs(a.v[k]); }); }
inline Mask4 operator<(Float4 a, Float4 b) { return masks4([&](int k) { return a.v[k] < b.v[k]; }); }
inline Mask4 operator<=(Float4 a, Float4 b) { return masks4([&](int k) { return a.v[k] <= b.v[k]; }); }
inline Mask4 operator>(Float4 a, Float4 b) { return masks4([&](int k) { return a.v[k] > b.v[k]; }); }
inline Mask4 operator&(Mask4 a, Mask4 b) { return masks4([&](int k) { return a.v[k] && b.v[k]; }); }
inline Mask4 operator|(Mask4 a, Mask4 b) { return masks4([&](int k) { return a.v[k] || b.v[k]; }); }
inline Float4 select(Mask4 m, Float4 a, Float4 b) { return lanes4([&](int k) { return m.v[k] ? a.v[k] : b.v[k]; }); }

#endif

}  // namespace pathlab
