// BMP decoding by stb_image, compiled into pathlab like the PNG decoder (stb_png.hpp): only its
// BMP decoder is included, and everything it allocates is held to a memory budget.
#pragma once

#include "image/stb_png.hpp"

namespace pathlab::io {

using BmpDecodeResult = PngDecodeResult;

// Decodes `size` bytes of a Windows BMP (1, 4, 8, 16, 24 or 32 bits per pixel; uncompressed,
// RLE or bit fields) into 8-bit RGB (`size` below 2^31). Everything stb allocates at once must
// fit in `budget` bytes.
BmpDecodeResult decode_bmp_rgb8(const uint8_t* data, size_t size, size_t budget, Image8& out);

}  // namespace pathlab::io
