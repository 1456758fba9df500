// The body of the image-reader fuzz targets (fuzz_exr, fuzz_hdr, fuzz_pfm, fuzz_png): any
// input must load or fail with an ImageIoError; crashes, hangs, sanitizer reports, other
// exceptions and allocations beyond libFuzzer's -malloc_limit_mb are bugs. Images are limited
// to 2^20 pixels (12 MiB) so that a valid header of a large image is not mistaken for a blow-up.
#pragma once

#include <cstddef>
#include <cstdint>

#include "image/image_io.hpp"

namespace pathlab::fuzz {

inline int read_image_input(ImageFormat format, const char* name, const uint8_t* data, size_t size) {
    static const ImageReadLimits limits{uint64_t(1) << 20};
    try {
        if (format == ImageFormat::Png) {
            const Image8 img = read_png8_from_memory(data, size, name, limits);
            if (img.rgb.size() != size_t(img.width) * size_t(img.height) * 3) __builtin_trap();
        } else {
            const Image img = read_image_from_memory(format, data, size, name, limits);
            if (img.pixel_count() != size_t(img.width()) * size_t(img.height()) || img.pixel_count() == 0) __builtin_trap();
        }
    } catch (const ImageIoError&) {
    }
    return 0;
}

}  // namespace pathlab::fuzz
