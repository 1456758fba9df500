// A reader of Radiance RGBE (.hdr) files, written for pathlab (internal to src/image).
//
// The format (Greg Ward, "Real Pixels", Graphics Gems II; Radiance's documentation):
//   "#?RADIANCE" (or "#?RGBE", or any "#?" line), header lines "NAME=value" up to an empty
//   line (FORMAT=32-bit_rle_rgbe is the only format accepted; other lines are ignored, as
//   stb_image ignores them, EXPOSURE included), then the resolution line "-Y H +X W" (top row
//   first, left to right: the only orientation accepted), then H scanlines of W pixels. A
//   pixel is 4 bytes r, g, b, e with value (r, g, b) * 2^(e - 136) (0 when e = 0). A scanline
//   is one of
//    - run-length encoded (widths 8 to 32767): 2, 2, W >> 8, W & 255, then the 4 components
//      one after the other, each as runs: a byte n > 128 repeats the next byte n - 128 times,
//      a byte 1 <= n <= 128 is followed by n literal bytes;
//    - flat: W pixels of 4 bytes, where the pixel (1, 1, 1, n) repeats the previous pixel of
//      the scanline n << s times, s growing by 8 over consecutive repeat pixels (the old
//      Radiance encoding).
// Every length is checked against the scanline and the file: a corrupt or truncated file is
// an ImageIoError that says where, after a bounded amount of work (each step consumes input),
// and the image is only allocated once every scanline has been decoded successfully.
#pragma once

#include "image/file_io.hpp"
#include "image/image.hpp"
#include "image/image_io.hpp"

namespace pathlab::io {

Image read_rgbe(const ByteSource& src, const ImageReadLimits& limits);

}  // namespace pathlab::io
