// bitmap: an image looked up at uv (Mitsuba 3's `bitmap` texture).
//
// XML (Mitsuba 3 names):
//   filename     string     the image: .png, .jpg/.jpeg, .bmp (8-bit, sRGB), .exr, .hdr, .pfm (linear)
//   filter_type  string     bilinear (interpolate the four nearest texels) or nearest  default bilinear
//   wrap_mode    string     outside [0,1]^2: repeat, mirror or clamp                     default repeat
//   raw          boolean    keep 8-bit values as stored (v / 255) instead of decoding     default false
//                           sRGB to linear; for normal and bump maps
//   to_uv        transform  applied to uv before the lookup
// 8-bit images (PNG, JPEG) are sRGB-encoded colours, decoded to linear values unless `raw`;
// float images (EXR, HDR, PFM) are linear and used as they are. An alpha channel is ignored.
//
// Lookup (as Mitsuba 3 and Dr.Jit do): row 0 is the top of the image, at v in [0, 1/height);
// texel (i, j) is centred at ((i + 0.5) / width, (j + 0.5) / height). Nearest takes texel
// (floor(u' width), floor(v' height)); bilinear takes x = u' width - 1/2, y = v' height - 1/2,
// the four texels around (floor x, floor y) with weights (1 - fx)(1 - fy), fx (1 - fy),
// (1 - fx) fy, fx fy (fx, fy the fractional parts), each index wrapped on its own:
//   repeat  i mod n;   clamp  min(max(i, 0), n - 1);
//   mirror  m = i mod 2n, then m if m < n, else 2n - 1 - m (texel -1 is texel 0: the image and
//           its mirror image alternate, each texel repeated at the seam).
// The interpolation is computed as two nested linear interpolations a + (b - a) t, so that
// equal texels give exactly their value.
#pragma once

#include <string>
#include <vector>

#include "textures/texture_common.hpp"

namespace pathlab {

enum class FilterType : unsigned char { Bilinear, Nearest };
enum class WrapMode : unsigned char { Repeat, Mirror, Clamp };

class BitmapTexture {
public:
    // `texels`: width * height linear values, row-major, top row first. `colour`: the values
    // are colours (decoded from sRGB, or a float image) rather than raw data: a spectral
    // renderer would upsample only those.
    BitmapTexture(int width, int height, std::vector<Rgb> texels, FilterType filter = FilterType::Bilinear,
                  WrapMode wrap = WrapMode::Repeat, UvTransform to_uv = {}, bool colour = true, std::string name = {});

    Rgb eval(const Vec2f& uv) const;
    float eval_1(const Vec2f& uv) const;  // the scalar value (texture_common.hpp)
    // The gradient of eval_1 with respect to (u, v) (of the bilinear interpolant; zero for
    // nearest lookups, which are piecewise constant).
    Vec2f eval_1_grad(const Vec2f& uv) const;
    TexelFootprint footprint(const Vec2f& uv) const;

    // The texel index that `i` (an integer, possibly outside [0, n)) wraps to along an axis of
    // n texels.
    int wrap(double i, int n) const;
    int wrap_index(int i, int n) const;  // the same for an int (n < 2^29)

    int width() const { return width_; }
    int height() const { return height_; }
    const std::vector<Rgb>& texels() const { return texels_; }
    FilterType filter() const { return filter_; }
    WrapMode wrap_mode() const { return wrap_; }
    const UvTransform& to_uv() const { return to_uv_; }
    bool colour() const { return colour_; }
    bool monochrome() const { return monochrome_; }  // every texel grey
    const std::string& name() const { return name_; }
    Rgb min_value() const { return min_; }
    Rgb max_value() const { return max_; }

private:
    // Where a lookup falls: the texels' columns and rows and the fractions between them.
    struct Cell {
        int x0, x1, y0, y1;
        float fx, fy;
    };
    Cell bilinear_cell(const Vec2f& uv) const;
    size_t index(int x, int y) const { return size_t(y) * size_t(width_) + size_t(x); }
    float scalar(size_t i) const { return monochrome_ ? texels_[i].x : luminance(texels_[i]); }

    int width_ = 0, height_ = 0;
    std::vector<Rgb> texels_;
    FilterType filter_;
    WrapMode wrap_;
    UvTransform to_uv_;
    bool colour_ = true, monochrome_ = true;
    std::string name_;
    Rgb min_{0.0f}, max_{0.0f};
};

// Reads a bitmap's image: PNG and JPEG through pathlab's guarded stb decoders (sRGB decoded to
// linear unless `raw`), EXR, HDR and PFM as linear values. Throws ImageIoError naming the file
// for an unreadable, truncated or unsupported image, and for non-finite texels.
BitmapTexture load_bitmap_texture(const std::string& path, bool raw, FilterType filter = FilterType::Bilinear,
                                  WrapMode wrap = WrapMode::Repeat, UvTransform to_uv = {});

}  // namespace pathlab
