// libFuzzer target for the IES (LM-63) photometric file parser (lights/ies_profile.hpp): any
// input must parse or fail with an IesError naming the input ("fuzz.ies:LINE: ..." or
// "fuzz.ies: ..."); a parsed profile must build its distribution with finite, non-negative
// candela, a finite flux, and samples whose densities are finite, positive and equal to pdf().
// Built and run by scripts/fuzz.sh ies.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "lights/ies_profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const pathlab::IesProfile p = pathlab::parse_ies(text, "fuzz.ies");
        if (p.values.size() != p.vertical.size() * p.horizontal.size()) __builtin_trap();
        const pathlab::IesDistribution d(p);
        if (!std::isfinite(d.flux()) || d.flux() < 0) __builtin_trap();
        for (int i = 0; i < 16; ++i) {
            const float u = (i + 0.5f) / 16, v = std::fmod(u * 7.31f, 1.0f);
            const float c = d.candela(double(u) * 180, double(v) * 720 - 180);
            if (!std::isfinite(c) || c < 0) __builtin_trap();
            float pdf = 0;
            if (const auto w = d.sample({u, v}, pdf)) {
                if (!std::isfinite(pdf) || !(pdf > 0) || pdf != d.pdf(*w)) __builtin_trap();
                if (!(std::abs(w->x * w->x + w->y * w->y + w->z * w->z - 1) < 1e-3f)) __builtin_trap();
            }
        }
    } catch (const pathlab::IesError& e) {
        if (std::strncmp(e.what(), "fuzz.ies", 8) != 0) __builtin_trap();
    }
    return 0;
}
