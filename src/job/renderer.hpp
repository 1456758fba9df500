// The render driver: calls an integrator's passes, in batches, until a sample count or a time
// budget is reached or the render is cancelled, and measures what was done. Small images run
// several passes per call (a batch) to keep every core busy; the batch grows while a batch
// takes under ~50 ms. Integrators make each pass a pure function of (seed, pass index), so the
// result is bit-identical for any thread count and any batching, and a render continued into
// the same film (first_sample) equals the one-shot render.
//
// Several processes (settings.ranks, e.g. MPI ranks) render one image together in rounds: each
// round takes the next passes still to do (of [first_sample, first_sample + spp), or without
// bound under a time budget), splits them into one contiguous part per rank, and ends with a
// collective that tells every rank the slowest part's time, the time spent and whether any rank
// was interrupted; every decision (the next round's size, stopping, checkpointing) is made
// from those shared figures, so all ranks agree on it, and the passes done after any round are
// the same set everywhere. At the end the ranks' films are summed into the root's (exact, so
// equal bit for bit to one process's film of the same passes; docs/distributed.md).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "job/pass_set.hpp"
#include "job/rank_group.hpp"
#include "render/film.hpp"

namespace pathlab {

// What one rank did (a render across processes reports each).
struct RankStats {
    std::string name;   // "rank 1 (host)"
    uint64_t spp = 0;   // passes this rank rendered
    double seconds = 0; // time in its passes
    uint64_t rays = 0;
};

struct RenderStats {
    uint64_t spp = 0;              // passes in the film (samples per pixel), resumed ones included
    uint64_t resumed_spp = 0;      // ... of which a resumed checkpoint held
    PassSet passes;                // the passes in the film
    double seconds = 0;            // wall-clock time of this run (the preparation and the passes)
    uint64_t samples = 0;          // pixel samples (or light paths) taken in this run: (spp - resumed) x pixels
    uint64_t rays = 0;             // rays traced (camera, shadow, continuation, light paths)
    uint64_t invalid_samples = 0;  // NaN/Inf samples, discarded (not averaged in)
    bool interrupted = false;      // stopped by the cancel flag
    std::vector<IntegratorStatistic> integrator;  // the integrator's own figures (ic: records, cache time)
    // Across processes (on the root): each rank's part, and the time the film reduction took.
    std::vector<RankStats> ranks;
    double reduce_seconds = 0;
    // Checkpoints written during this run (and those that could not be), and the time they took.
    uint64_t checkpoints = 0, failed_checkpoints = 0;
    bool last_checkpoint_failed = false;  // the final one: the file keeps an earlier state
    double checkpoint_seconds = 0;
};

struct RenderSettings {
    int width = 0, height = 0;  // 0: the scene's default resolution
    uint64_t spp = 0;           // samples per pixel to take; 0: until the time budget ends
    double time_limit = 0;      // seconds; 0: none
    uint64_t seed = 0;
    SamplerKind sampler = SamplerKind::Independent;
    bool spectral = false;      // spectral mode: the integrator was made for it (IntegratorOptions::spectral); outputs say so
    uint64_t first_sample = 0;  // sample index of the first pass
    int tile_size = 32;         // largest tile edge; smaller when the image has too few tiles
    bool progress = false;      // progress line on stderr
    const std::atomic<bool>* cancel = nullptr;  // checked after every batch of passes
    // Called after every batch of passes (for convergence checkpoints); may be empty. Not
    // called when several ranks render (each holds only a part of the film).
    std::function<void(const Film&, const RenderStats&)> after_pass;

    // The image as it converges (--display-server): display(film, stats) is called on the root
    // after the first round, then after a round at most every display_every seconds (less often
    // when showing the image takes over 5% of the time), and with the final film. With several ranks their films are summed for it (every rank takes part,
    // so display must be set on all of them). It only reads the film: the render is the same
    // with and without it.
    std::function<void(const Film&, const RenderStats&)> display;
    double display_every = 0.5;

    // --aovs: the integrator's camera samples' first vertices, summed into this film of the
    // render's size (render/aov_film.hpp); null: none. Only a pixel integrator records them, and
    // only in one process (the film is not reduced across ranks).
    AovFilm* aovs = nullptr;

    // The processes rendering this image together; null: this one alone.
    RankGroup* ranks = nullptr;
    // Passes the film already holds (a resumed checkpoint; only the root's film holds them),
    // the same on every rank; they must lie in the render's range and are not rendered again.
    PassSet done;
    // Checkpoints: checkpoint(parts, film, done, stats) is called every checkpoint_every
    // seconds (0: never) after a round, on every rank with its own film and parts = the ranks
    // (it sums them with parts.reduce_film), and at the end, also of an interrupted render, on
    // the root alone with the summed film and parts = one process. It returns whether the
    // checkpoint was written (a failed one is counted apart; the render goes on).
    double checkpoint_every = 0;
    std::function<bool(RankGroup& parts, const Film& film, const PassSet& done, const RenderStats& stats)> checkpoint;
};

struct RenderResult {
    Film film;
    RenderStats stats;
};

// A render whose film does not fit in memory (FilmTooLarge says how much it needs).
struct FilmTooLarge : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// What a render holds per pixel: the film's exact sums, squares and count (160 bytes), a pass
// image for splatting integrators (24) and the mean and standard-error images written at the
// end (24).
constexpr uint64_t kRenderBytesPerPixel = sizeof(PixelSums) + 48;
// A film of w x h pixels, or a FilmTooLarge saying how much memory it needs.
Film make_film(int w, int h);

// Throws std::invalid_argument for a non-positive resolution, or when neither spp nor a time
// limit bounds the render, and FilmTooLarge before allocating a film that does not fit.
RenderResult render(const Scene& scene, Integrator& integrator, const RenderSettings& settings);
inline RenderResult render(const Scene& scene, Integrator&& integrator, const RenderSettings& settings) {
    return render(scene, integrator, settings);
}
// The same, adding the passes to `film` (which must have the settings' resolution): a render
// continued from where another stopped (settings.first_sample = its spp, or settings.done =
// its passes) ends bit-identical to the one-shot render. With several ranks, the root's film
// holds the sum at the end and the other ranks' films their own parts.
RenderStats render_into(const Scene& scene, Integrator& integrator, const RenderSettings& settings, Film& film);

}  // namespace pathlab
