#include "job/renderer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <stdexcept>

#include <fmt/format.h>

#include "render/progress.hpp"

namespace pathlab {

RenderResult render(const Scene& scene, const Estimator& estimator, const RenderSettings& settings) {
    const int w = settings.width > 0 ? settings.width : scene.default_width();
    const int h = settings.height > 0 ? settings.height : scene.default_height();
    if (w <= 0 || h <= 0 || settings.width < 0 || settings.height < 0)
        throw std::invalid_argument(fmt::format("resolution must be positive, got {}x{}", w, h));
    if (settings.spp <= 0 && settings.time_limit <= 0)
        throw std::invalid_argument("a render needs a positive sample count or time limit");

    RenderResult result{Film(w, h), {}};
    const CameraRays camera(scene.camera(), w, h);
    // Tiles small enough that every worker gets several (small images still use all cores).
    const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
    int ts = std::max(1, settings.tile_size);
    while (ts > 4 && ((w + ts - 1) / ts) * ((h + ts - 1) / ts) < 4 * workers) ts /= 2;
    const int tiles_x = (w + ts - 1) / ts, tiles_y = (h + ts - 1) / ts;
    const int tile_count = tiles_x * tiles_y;

    Progress progress(settings.progress);
    const auto start = std::chrono::steady_clock::now();
    const auto seconds_since_start = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    std::atomic<uint64_t> rays{0}, invalid{0};
    std::atomic<int> tiles_done{0};

    // Passes run in batches of one parallel loop each; the batch grows while a batch takes
    // under ~50 ms, so small images do not pay a loop's overhead per sample. Pixels take their
    // samples in index order whatever the batching, so results do not depend on it.
    int done = 0, batch = 1;
    RenderStats& st = result.stats;
    while (settings.spp <= 0 || done < settings.spp) {
        const int passes = settings.spp > 0 ? std::min(batch, settings.spp - done) : batch;
        const double batch_start = seconds_since_start();
        tiles_done = 0;
        tbb::parallel_for(tbb::blocked_range<int>(0, tile_count, 1), [&](const tbb::blocked_range<int>& range) {
            for (int tile = range.begin(); tile != range.end(); ++tile) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t tile_invalid = 0;
                const int x0 = (tile % tiles_x) * ts, y0 = (tile / tiles_x) * ts;
                for (int y = y0; y < std::min(y0 + ts, h); ++y)
                    for (int x = x0; x < std::min(x0 + ts, w); ++x) {
                        const size_t pixel = size_t(y) * size_t(w) + size_t(x);
                        for (int k = 0; k < passes; ++k) {
                            Sampler sampler(settings.seed, pixel, settings.first_sample + uint64_t(done + k), settings.sampler);
                            const Vec2f jitter = sampler.next2d();
                            const Ray ray = camera.generate(float(x) + jitter.x, float(y) + jitter.y);
                            const Rgb L = estimator.radiance(scene, ray, sampler);
                            if (is_finite(L)) result.film.add(pixel, L);
                            else ++tile_invalid;
                        }
                    }
                rays += Scene::rays_traced_by_this_thread() - rays_before;
                invalid += tile_invalid;
                const int finished = ++tiles_done;
                if (settings.progress) {
                    const double within = double(done) + double(passes) * finished / tile_count;
                    double fraction = settings.spp > 0 ? within / settings.spp : 0;
                    if (settings.time_limit > 0) fraction = std::max(fraction, seconds_since_start() / settings.time_limit);
                    progress.update(std::min(fraction, 1.0), uint64_t(within * double(w) * double(h)),
                                    fmt::format("{} spp", done));
                }
            }
        });
        done += passes;
        st.spp = done;
        st.samples = uint64_t(done) * uint64_t(w) * uint64_t(h);
        st.rays = rays;
        st.invalid_samples = invalid;
        st.seconds = seconds_since_start();
        const double batch_seconds = st.seconds - batch_start;
        if (settings.after_pass) settings.after_pass(result.film, st);
        if (settings.cancel && settings.cancel->load()) {
            st.interrupted = true;
            break;
        }
        // Stop when another batch would end further past the budget than stopping now ends short of it.
        if (settings.time_limit > 0) {
            const double per_pass = batch_seconds / passes;
            const double left = settings.time_limit - st.seconds;
            if (left <= 0.5 * per_pass) break;
            batch = std::max(1, std::min(batch, int(left / per_pass)));
        }
        if (batch_seconds < 0.05 && batch < (1 << 20)) batch *= 2;
    }
    progress.finish();
    return result;
}

}  // namespace pathlab
