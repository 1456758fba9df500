// JPEG decoding by stb_image, compiled into pathlab like the PNG decoder (stb_png.hpp): only its
// JPEG decoder is included, and everything it allocates is held to a memory budget.
#pragma once

#include "image/stb_png.hpp"

namespace pathlab::io {

using JpegDecodeResult = PngDecodeResult;

// Decodes `size` bytes of JPEG (baseline or progressive, 8 bits per sample, grey, YCbCr, RGB or
// CMYK) into 8-bit RGB (`size` below 2^31). Everything stb allocates at once must fit in
// `budget` bytes.
JpegDecodeResult decode_jpeg_rgb8(const uint8_t* data, size_t size, size_t budget, Image8& out);

}  // namespace pathlab::io
