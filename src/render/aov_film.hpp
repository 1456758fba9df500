// The auxiliary images (--aovs, what a denoiser takes beside the image): per pixel, the mean
// over its camera samples of what each sample's path saw at its first non-specular vertex (a
// surface whose BSDF is not only Dirac lobes, or a scattering point in a medium), through mirrors,
// glass and index-matched boundaries, taken from the image's own samples, not extra rays. A
// sample that finds no such vertex (the sky, or a path that ended on a specular surface)
// counts as zero in every channel. Each pixel sums its samples in sample-index order, so the
// images are the same bytes for any thread count.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

// What one camera sample saw first.
struct FirstVertex {
    bool found = false;
    Rgb albedo{0.0f};     // the surface's diffuse reflectance (textured: at its uv); a medium's sigma_s / sigma_t
    Vec3f normal{0.0f};   // the shading normal (world space, facing where the path came from); 0 in a medium
    Vec3f position{0.0f}; // world space
    float depth = 0;      // the path's length from the camera to it (through the specular vertices before it)
};

class AovFilm {
public:
    AovFilm() = default;
    AovFilm(int width, int height) : width_(width), height_(height), sums_(size_t(width) * size_t(height), Sums{}) {}
    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixel_count() const { return sums_.size(); }

    // One sample of a pixel (found or not).
    void add(size_t pixel, const FirstVertex& v);
    // The pixel's mean of component c: albedo 0-2, normal 3-5, position 6-8, depth 9.
    float mean(size_t pixel, int c) const {
        const Sums& s = sums_[pixel];
        return s.count ? float(s.sum[size_t(c)] / double(s.count)) : 0.0f;
    }
    uint64_t count(size_t pixel) const { return sums_[pixel].count; }
    // True when every pixel's sums equal the other's bit for bit.
    bool identical(const AovFilm& other) const;

    static constexpr int kComponents = 10;

private:
    struct Sums {
        std::array<double, kComponents> sum{};
        uint64_t count = 0;
    };
    int width_ = 0, height_ = 0;
    std::vector<Sums> sums_;
};

// The auxiliary images pathlab writes, as --aovs names them, with their EXR channels (pbrt-v4's
// GBufferFilm names where it has them; Z is OpenEXR's depth channel):
//   albedo        Albedo.R Albedo.G Albedo.B
//   normal        N.X N.Y N.Z
//   depth         Z
//   position      P.X P.Y P.Z
//   variance      Variance.R Variance.G Variance.B   (the variance of one sample of the pixel)
//   sample-count  SampleCount                         (the samples in the pixel)
const std::vector<std::string>& aov_names();
// The EXR channels of `aov` (one of aov_names()).
std::vector<std::string> aov_channel_names(const std::string& aov);
// Whether `aovs` needs the first-vertex sums (albedo, normal, depth, position), not only the film.
bool aovs_need_first_vertex(const std::vector<std::string>& aovs);

}  // namespace pathlab
