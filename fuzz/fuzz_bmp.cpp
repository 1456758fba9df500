// libFuzzer target for the .bmp reader (stb_image's BMP decoder under pathlab's checks and
// memory budget): any input must load or fail with an ImageIoError; crashes, hangs, sanitizer
// reports, other exceptions and allocations beyond libFuzzer's -malloc_limit_mb are bugs.
// Images are limited to 2^20 pixels, as for the other image readers. Built and run by
// scripts/fuzz.sh bmp.
#include <cstddef>
#include <cstdint>

#include "image/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const pathlab::ImageReadLimits limits{uint64_t(1) << 20};
    try {
        const pathlab::Image8 img = pathlab::read_bmp8_from_memory(data, size, "fuzz.bmp", limits);
        if (img.rgb.size() != size_t(img.width) * size_t(img.height) * 3 || img.rgb.empty()) __builtin_trap();
    } catch (const pathlab::ImageIoError&) {
    }
    return 0;
}
