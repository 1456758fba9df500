// libFuzzer target for the .vol voxel-grid reader (parse_vol): any input must load or fail with a
// GridFileError; a loaded grid must be usable (its size matching its dimensions and channels,
// every value finite and not negative, lookups finite). Built and run by scripts/fuzz.sh vol.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "media/grid_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        const pathlab::VoxelGrid g = pathlab::parse_vol(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.vol");
        if (g.channels != 1 && g.channels != 3) __builtin_trap();
        if (g.data.size() != g.voxel_count() * size_t(g.channels)) __builtin_trap();
        for (float v : g.data)
            if (!std::isfinite(v) || v < 0) __builtin_trap();
        for (float u : {0.0f, 0.3f, 0.5f, 1.0f}) {
            const pathlab::Rgb value = g.lookup({u, 1 - u, u * 0.5f});
            if (!pathlab::is_finite(value) || pathlab::min_component(value) < 0) __builtin_trap();
        }
        if (g.max_over({0, 0, 0}, {1, 1, 1}) != g.max_value()) __builtin_trap();
    } catch (const pathlab::GridFileError&) {
    }
    return 0;
}
