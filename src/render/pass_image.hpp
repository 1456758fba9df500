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

namespace pathlab {

struct Splat {
    uint32_t pixel;
    Rgb value;
};

class SplatList {
public:
    void add(uint32_t pixel, const Rgb& value) { splats_.push_back({pixel, value}); }
    void clear() { splats_.clear(); }
    const std::vector<Splat>& splats() const { return splats_; }

private:
    std::vector<Splat> splats_;  // keeps its capacity from pass to pass: no allocation once warm
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
    const std::vector<Vec3d>& values() const { return values_; }

private:
    std::vector<Vec3d> values_;
    std::vector<SplatList> lists_;
    int chunks_ = 0;
};

}  // namespace pathlab
