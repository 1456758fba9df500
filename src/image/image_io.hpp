// Reading and writing images. The format follows the file extension:
//   .exr  OpenEXR, 32-bit float RGB (linear)
//   .hdr  Radiance RGBE (linear, ~1% precision)
//   .pfm  portable float map, 32-bit float RGB (linear)
//   .png  8-bit sRGB, tone-mapped by exposure (write); 8-bit values (read_png8)
//   .jpg  8-bit values (read_jpeg8; baseline and progressive JPEG through stb_image; not written)
//   .bmp  8-bit values (read_bmp8; Windows BMP, uncompressed or bit fields, through stb_image; not written)
//
// Writing: every byte goes to a temporary file `.NAME.pathlab-tmp-PID-N` next to the target;
// each write, the flush, fsync and close are checked, and only then is the temporary renamed
// onto NAME. On any failure (a full disk, a file size limit, an I/O error) the temporary is
// removed, a file already at NAME is left as it was, and ImageIoError names the file and the
// reason. Temporaries of NAME left by a process that no longer exists (killed during a write)
// are removed by the next write of NAME.
//
// Reading never hangs, crashes or allocates more than the image needs: only regular files are
// read (not devices, FIFOs or directories); every header is checked against the file's size
// before anything is allocated; images of more than kMaxImagePixels pixels are refused with a
// message saying how much memory they would need. Every failure is an ImageIoError naming the
// file and the problem.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "image/image.hpp"

namespace pathlab {

struct ImageIoError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

enum class ImageFormat { Exr, Hdr, Pfm, Png };

// The largest image the readers accept: 2^28 pixels (16384 x 16384), which take 3 GiB as
// linear RGB floats.
constexpr uint64_t kMaxImagePixels = uint64_t(1) << 28;

struct ImageReadLimits {
    uint64_t max_pixels = kMaxImagePixels;
};

// The format for a path's extension (case-insensitive); throws ImageIoError listing the
// supported extensions otherwise.
ImageFormat image_format_for(const std::string& path);

// Checks before a long render that `path` has a known extension and can be written: creates
// missing parent directories and a temporary file there, then removes it.
void check_writable_image_path(const std::string& path);

// The same for a text output (--stats, --json): not a directory, and a file can be made there.
void check_writable_path(const std::string& path);
void write_image(const Image& img, const std::string& path, float png_exposure = 0.0f);
void write_png8(const Image8& img, const std::string& path);

// One extra EXR channel: width x height floats, row by row (e.g. "m2.R", "dd.Y").
struct ExrChannel {
    std::string name;
    std::vector<float> values;
};
// An EXR's content beyond its RGB image: RGB layers (channels "<name>.R", "<name>.G",
// "<name>.B"; a render's "stderr"), single channels (the moment and aov integrators') and
// string attributes of the header (a render's "pathlab:spp", "pathlab:seed", ...; README,
// "Rendering across processes"). Reading fills the layers and attributes.
struct ExrExtras {
    std::vector<std::pair<std::string, Image>> layers;
    std::vector<std::pair<std::string, std::string>> attributes;
    std::vector<ExrChannel> channels;
};
// Writes an .exr with its extras (atomically, as write_image).
void write_exr(const Image& img, const ExrExtras& extras, const std::string& path);
// Reads an .exr's RGB image and fills `extras` with its RGB layers and string attributes.
Image read_exr(const std::string& path, ExrExtras& extras, const ImageReadLimits& limits = {});

// Reads a linear HDR image (.exr, .hdr or .pfm).
Image read_image(const std::string& path, const ImageReadLimits& limits = {});
// Reads an 8-bit PNG as stored (no decoding of its transfer curve).
Image8 read_png8(const std::string& path, const ImageReadLimits& limits = {});
// Reads an 8-bit JPEG as stored (grey and CMYK converted to RGB by stb_image). A file that
// ends before its end-of-image marker is refused as truncated.
Image8 read_jpeg8(const std::string& path, const ImageReadLimits& limits = {});
// Reads an 8-bit Windows BMP as stored (1 to 32 bits per pixel; palettes expanded; RLE refused).
Image8 read_bmp8(const std::string& path, const ImageReadLimits& limits = {});

// The same readers on bytes in memory, as if they were the file `name` (which only appears in
// messages). For the fuzzers and the tests.
Image read_image_from_memory(ImageFormat format, const void* data, size_t size, const std::string& name,
                             const ImageReadLimits& limits = {});
Image8 read_png8_from_memory(const void* data, size_t size, const std::string& name, const ImageReadLimits& limits = {});
Image8 read_jpeg8_from_memory(const void* data, size_t size, const std::string& name, const ImageReadLimits& limits = {});
Image8 read_bmp8_from_memory(const void* data, size_t size, const std::string& name, const ImageReadLimits& limits = {});

// Writes `text` to `path` atomically, with the same checks as the images.
void write_text_file(const std::string& path, const std::string& text);

// The encoders behind write_image, write_png8 and write_text_file, writing to an open file
// descriptor `fd` (left open) and flushing; `name` appears in messages. Throw ImageIoError on
// any failed write. For the tests, which point them at /dev/full.
void write_image_to_fd(const Image& img, ImageFormat format, int fd, const std::string& name, float png_exposure = 0.0f);
void write_png8_to_fd(const Image8& img, int fd, const std::string& name);
void write_text_to_fd(const std::string& text, int fd, const std::string& name);

// The prefix of the temporary files that writing `path` creates: ".NAME.pathlab-tmp-"
// (followed by "PID-N"), in the same directory.
std::string temporary_prefix_for(const std::string& path);

}  // namespace pathlab
