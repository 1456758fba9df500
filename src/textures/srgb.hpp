// The sRGB transfer curve (IEC 61966-2-1): 8-bit sRGB-encoded values to linear ones.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace pathlab {

// Linear value of an sRGB-encoded one in [0, 1].
inline double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// The linear value of each 8-bit code, computed once in double precision.
inline const std::array<float, 256>& srgb8_to_linear_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = float(srgb_to_linear(i / 255.0));
        return t;
    }();
    return table;
}

}  // namespace pathlab
