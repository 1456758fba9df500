// The render driver: progressive passes of one sample per pixel over image tiles, in parallel
// with oneTBB, until a sample count or a time budget is reached or the render is cancelled.
// Small images run several passes per parallel loop (a batch) to keep every core busy.
// Sample s of pixel p always uses Sampler(seed, p, s), and each pixel accumulates its samples
// in index order, so the result is bit-identical for any thread count, and a render split into
// parts (first_sample) sums to the one-shot render.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>

#include "integrators/integrator.hpp"
#include "render/film.hpp"

namespace pathlab {

struct RenderStats {
    int spp = 0;                   // passes completed (samples per pixel)
    double seconds = 0;            // wall-clock time of the passes
    uint64_t samples = 0;          // camera samples taken
    uint64_t rays = 0;             // rays traced (camera, shadow, continuation)
    uint64_t invalid_samples = 0;  // NaN/Inf samples, discarded (not averaged in)
    bool interrupted = false;      // stopped by the cancel flag
};

struct RenderSettings {
    int width = 0, height = 0;  // 0: the scene's default resolution
    int spp = 0;                // samples per pixel to take; 0: until the time budget ends
    double time_limit = 0;      // seconds; 0: none
    uint64_t seed = 0;
    SamplerKind sampler = SamplerKind::Independent;
    uint64_t first_sample = 0;  // sample index of the first pass
    int tile_size = 32;         // largest tile edge; smaller when the image has too few tiles
    bool progress = false;      // progress line on stderr
    const std::atomic<bool>* cancel = nullptr;  // checked after every batch of passes
    // Called after every batch of passes (for convergence checkpoints); may be empty.
    std::function<void(const Film&, const RenderStats&)> after_pass;
};

struct RenderResult {
    Film film;
    RenderStats stats;
};

// Throws std::invalid_argument for a non-positive resolution, or when neither spp nor a time
// limit bounds the render.
RenderResult render(const Scene& scene, const Estimator& estimator, const RenderSettings& settings);

}  // namespace pathlab
