// The tile loop of pixel integrators: tiles in parallel, and within a tile every pixel takes
// its samples of this call in index order, so the result does not depend on threads or tiles.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>

#include "integrators/common/camera_ray.hpp"
#include "integrators/integrator.hpp"

namespace pathlab {

template <class T>
PassCounters PixelIntegrator<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                                               const PassProgress& progress) {
    if (ctx.filter && !ctx.filter->is_box()) return render_filtered_passes(ctx, film, first, count, progress);
    const int w = ctx.width, h = ctx.height;
    // Tiles small enough that every worker gets several (small images still use all cores).
    const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
    int ts = std::max(1, ctx.tile_size);
    while (ts > 4 && ((w + ts - 1) / ts) * ((h + ts - 1) / ts) < 4 * workers) ts /= 2;
    const int tiles_x = (w + ts - 1) / ts, tiles_y = (h + ts - 1) / ts;
    const int tile_count = tiles_x * tiles_y;

    std::atomic<uint64_t> rays{0}, invalid{0};
    std::atomic<int> tiles_done{0};
    tbb::parallel_for(tbb::blocked_range<int>(0, tile_count, 1), [&](const tbb::blocked_range<int>& range) {
        for (int tile = range.begin(); tile != range.end(); ++tile) {
            const uint64_t rays_before = Scene::rays_traced_by_this_thread();
            uint64_t tile_invalid = 0;
            const int x0 = (tile % tiles_x) * ts, y0 = (tile / tiles_x) * ts;
            for (int y = y0; y < std::min(y0 + ts, h); ++y)
                for (int x = x0; x < std::min(x0 + ts, w); ++x) {
                    const size_t pixel = size_t(y) * size_t(w) + size_t(x);
                    for (int k = 0; k < count; ++k) {
                        Sampler sampler(ctx.seed, pixel, first + uint64_t(k), ctx.sampler);
                        const Vec2f jitter = sampler.next2d();
                        const Ray ray = camera_ray(ctx.camera, float(x) + jitter.x, float(y) + jitter.y, sampler);
                        const Vec3d L = sample_colour(ctx, ray, sampler, pixel);
                        if (is_finite(L)) film.add(pixel, L);
                        else ++tile_invalid;
                    }
                }
            rays += Scene::rays_traced_by_this_thread() - rays_before;
            invalid += tile_invalid;
            if (progress) progress(double(++tiles_done) / tile_count);
        }
    });
    return {rays.load(), invalid.load()};
}

// With a reconstruction filter (render/pixel_filter.hpp): pass by pass, every pixel's sample at
// the pass's lattice shift, then the pass filtered into the film as one sample of every pixel.
// The pixel's own jitter is drawn and not used, so the rest of its random numbers are those of
// the unfiltered render.
template <class T>
PassCounters PixelIntegrator<T>::render_filtered_passes(const RenderContext& ctx, Film& film, uint64_t first, int count,
                                                     const PassProgress& progress) {
    const int w = ctx.width, h = ctx.height;
    const int rows_per_task = std::max(1, 1024 / std::max(1, w));
    const int tasks = (h + rows_per_task - 1) / rows_per_task;
    lattice_.assign(ctx.pixel_count(), Vec3d(0.0));
    std::atomic<uint64_t> rays{0}, invalid{0};
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        const Vec2f shift = filter_shift(ctx, pass);
        std::atomic<int> done{0};
        tbb::parallel_for(tbb::blocked_range<int>(0, tasks, 1), [&](const tbb::blocked_range<int>& range) {
            for (int task = range.begin(); task != range.end(); ++task) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t task_invalid = 0;
                for (int y = task * rows_per_task; y < std::min(h, (task + 1) * rows_per_task); ++y)
                    for (int x = 0; x < w; ++x) {
                        const size_t pixel = size_t(y) * size_t(w) + size_t(x);
                        Sampler sampler(ctx.seed, pixel, pass, ctx.sampler);
                        sampler.next2d();  // the unfiltered render's jitter
                        const float sx = float(x) + shift.x, sy = float(y) + shift.y;
                        const Ray ray = camera_ray(ctx.camera, sx, sy, sampler);
                        const Vec3d L = sample_colour(ctx, ray, sampler, pixel);
                        if (is_finite(L)) {
                            lattice_[pixel] = L;
                        } else {
                            lattice_[pixel] = Vec3d(0.0);
                            ++task_invalid;
                        }
                    }
                rays += Scene::rays_traced_by_this_thread() - rays_before;
                invalid += task_invalid;
                if (progress) progress((double(k) + double(++done) / tasks) / count);
            }
        });
        ctx.filter->filter_pass(lattice_, shift, filtered_);
        film.add_pass(filtered_);
    }
    return {rays.load(), invalid.load()};
}

Vec2f filter_shift(const RenderContext& ctx, uint64_t pass) {
    // A stream no pixel or path index uses.
    Sampler sampler(ctx.seed, ~uint64_t(0), pass, ctx.sampler);
    return sampler.next2d();
}

template class PixelIntegrator<RgbTransport>;
template class PixelIntegrator<SpectralTransport>;

}  // namespace pathlab
