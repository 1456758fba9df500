// PNG decoding by stb_image, compiled into pathlab (internal to src/image) so that it can be
// held to a memory budget and fuzzed with sanitizers; only its PNG decoder is included.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "image/image.hpp"

namespace pathlab::io {

struct PngDecodeResult {
    bool ok = false;
    bool over_budget = false;  // stb asked for more memory than `budget` in total
    std::string error;         // stb's reason when !ok
};

// Decodes `size` bytes of PNG into 8-bit RGB (`size` below 2^31). Everything stb allocates at
// once must fit in `budget` bytes, so that corrupt data cannot make it allocate without bound.
PngDecodeResult decode_png_rgb8(const uint8_t* data, size_t size, size_t budget, Image8& out);

}  // namespace pathlab::io
