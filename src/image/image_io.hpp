// Reading and writing images. The format follows the file extension:
//   .exr  OpenEXR, 32-bit float RGB (linear)
//   .hdr  Radiance RGBE (linear, ~1% precision)
//   .pfm  portable float map, 32-bit float RGB (linear)
//   .png  8-bit sRGB, tone-mapped by exposure (write); 8-bit values (read_png8)
// Writes go to a temporary file in the target directory that is renamed into place, so a
// crash or interruption never leaves a half-written image. Errors throw ImageIoError naming
// the file.
#pragma once

#include <stdexcept>
#include <string>

#include "image/image.hpp"

namespace pathlab {

struct ImageIoError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

enum class ImageFormat { Exr, Hdr, Pfm, Png };

// The format for a path's extension (case-insensitive); throws ImageIoError listing the
// supported extensions otherwise.
ImageFormat image_format_for(const std::string& path);

// Checks before a long render that `path` has a known extension and can be written: creates
// missing parent directories and a temporary file there, then removes it.
void check_writable_image_path(const std::string& path);

void write_image(const Image& img, const std::string& path, float png_exposure = 0.0f);
void write_png8(const Image8& img, const std::string& path);

// Reads a linear HDR image (.exr, .hdr or .pfm).
Image read_image(const std::string& path);
// Reads an 8-bit PNG as stored (no decoding of its transfer curve).
Image8 read_png8(const std::string& path);

// Writes `text` to `path` atomically (temporary file + rename).
void write_text_file(const std::string& path, const std::string& text);

}  // namespace pathlab
