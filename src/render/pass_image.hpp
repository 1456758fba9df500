// One pass of an integrator that adds contributions to arbitrary pixels (splats): a light
// tracer connects each light-path vertex to the camera, BDPT adds its t = 1 strategies.
//
// Determinism: the pass's work is divided into a fixed number of chunks (independent of the
// thread count); each chunk records its splats, in the order it makes them, in its own list,
// and finish() adds the lists into the pass image in chunk order. So the image is bit-identical
// whichever thread ran which chunk. Contributions that belong to one pixel (a camera path of
// that pixel) may be added to the pass image directly by the thread that owns the pixel.
// Measured against accumulating into fixed-point integers with atomics: bench/ (`pathlab_bench
// splat`), figures in README.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "render/film.hpp"
#include "render/pixel_filter.hpp"

namespace pathlab {

struct Splat {
    uint32_t pixel;
    Rgb value;
};

// A splat at a raster position, spread by a reconstruction filter (pixel_filter.hpp).
struct RasterSplat {
    Vec2f raster;
    Rgb value;
};

class SplatList {
public:
    void add(uint32_t pixel, const Rgb& value) { splats_.push_back({pixel, value}); }
    void add_at(const Vec2f& raster, const Rgb& value) { raster_splats_.push_back({raster, value}); }
    void clear() {
        splats_.clear();
        raster_splats_.clear();
    }
    const std::vector<Splat>& splats() const { return splats_; }
    const std::vector<RasterSplat>& raster_splats() const { return raster_splats_; }

private:
    std::vector<Splat> splats_;  // keeps its capacity from pass to pass: no allocation once warm
    std::vector<RasterSplat> raster_splats_;
};

class PassImage {
public:
    // Prepares a pass of `chunks` chunks for a film of `pixels` pixels (memory is reused).
    void begin(size_t pixels, int chunks) {
        values_.assign(pixels, Vec3d(0.0));
        if (lists_.size() < size_t(chunks)) lists_.resize(size_t(chunks));
        chunks_ = chunks;
        for (int k = 0; k < chunks; ++k) lists_[size_t(k)].clear();
    }
    SplatList& chunk(int k) { return lists_[size_t(k)]; }
    // Per-pixel contributions (for the thread that owns the pixel in this pass).
    Vec3d& pixel(size_t p) { return values_[p]; }

    // Adds the chunks' splats in chunk order, then the pass as one sample of every pixel.
    void finish(Film& film) {
        for (int k = 0; k < chunks_; ++k)
            for (const Splat& s : lists_[size_t(k)].splats()) values_[s.pixel] += Vec3d(s.value);
        film.add_pass(values_);
    }
    // With a reconstruction filter: the per-pixel contributions are the pass's lattice samples
    // (at pixel + shift), filtered; the raster splats are spread in chunk order; then the pass.
    void finish(Film& film, const PixelFilter* filter, const Vec2f& shift) {
        if (!filter || filter->is_box()) return finish(film);
        filter->filter_pass(values_, shift, filtered_);
        for (int k = 0; k < chunks_; ++k) {
            for (const Splat& s : lists_[size_t(k)].splats()) filtered_[s.pixel] += Vec3d(s.value);
            for (const RasterSplat& s : lists_[size_t(k)].raster_splats()) filter->splat(s.raster, Vec3d(s.value), filtered_);
        }
        film.add_pass(filtered_);
    }
    const std::vector<Vec3d>& values() const { return values_; }

private:
    std::vector<Vec3d> values_, filtered_;
    std::vector<SplatList> lists_;
    int chunks_ = 0;
};

}  // namespace pathlab
