// The render driver: calls an integrator's passes, in batches, until a sample count or a time
// budget is reached or the render is cancelled, and measures what was done. Small images run
// several passes per call (a batch) to keep every core busy; the batch grows while a batch
// takes under ~50 ms. Integrators make each pass a pure function of (seed, pass index), so the
// result is bit-identical for any thread count and any batching, and a render continued into
// the same film (first_sample) equals the one-shot render.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>

#include "integrators/integrator.hpp"
#include "render/film.hpp"

namespace pathlab {

struct RenderStats {
    uint64_t spp = 0;              // passes completed (samples per pixel)
    double seconds = 0;            // wall-clock time of the passes
    uint64_t samples = 0;          // pixel samples (or light paths) taken: spp x pixels
    uint64_t rays = 0;             // rays traced (camera, shadow, continuation, light paths)
    uint64_t invalid_samples = 0;  // NaN/Inf samples, discarded (not averaged in)
    bool interrupted = false;      // stopped by the cancel flag
    std::vector<IntegratorStatistic> integrator;  // the integrator's own figures (ic: records, cache time)
};

struct RenderSettings {
    int width = 0, height = 0;  // 0: the scene's default resolution
    uint64_t spp = 0;           // samples per pixel to take; 0: until the time budget ends
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

// A render whose film does not fit in memory (FilmTooLarge says how much it needs).
struct FilmTooLarge : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// What a render holds per pixel: the film's sums, squares and count (56 bytes), a pass image
// for splatting integrators (24) and the mean and standard-error images written at the end (24).
constexpr uint64_t kRenderBytesPerPixel = 104;

// Throws std::invalid_argument for a non-positive resolution, or when neither spp nor a time
// limit bounds the render, and FilmTooLarge before allocating a film that does not fit.
RenderResult render(const Scene& scene, Integrator& integrator, const RenderSettings& settings);
inline RenderResult render(const Scene& scene, Integrator&& integrator, const RenderSettings& settings) {
    return render(scene, integrator, settings);
}
// The same, adding the passes to `film` (which must have the settings' resolution): a render
// continued from where another stopped (settings.first_sample = its spp) ends bit-identical
// to the one-shot render.
RenderStats render_into(const Scene& scene, Integrator& integrator, const RenderSettings& settings, Film& film);

}  // namespace pathlab
