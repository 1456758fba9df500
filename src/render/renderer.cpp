#include "render/renderer.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <stdexcept>

#include <fmt/format.h>

#include "core/progress.hpp"

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
    const int ts = std::max(1, settings.tile_size);
    const int tiles_x = (w + ts - 1) / ts, tiles_y = (h + ts - 1) / ts;
    const int tile_count = tiles_x * tiles_y;

    Progress progress(settings.progress);
    const auto start = std::chrono::steady_clock::now();
    const auto seconds_since_start = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    std::atomic<uint64_t> rays{0}, invalid{0};
    std::atomic<int> tiles_done{0};
    double last_pass_seconds = 0;

    for (int pass = 0; settings.spp <= 0 || pass < settings.spp; ++pass) {
        const uint64_t sample_index = settings.first_sample + uint64_t(pass);
        const double pass_start = seconds_since_start();
        tiles_done = 0;
        tbb::parallel_for(tbb::blocked_range<int>(0, tile_count, 1), [&](const tbb::blocked_range<int>& range) {
            for (int tile = range.begin(); tile != range.end(); ++tile) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t tile_invalid = 0;
                const int x0 = (tile % tiles_x) * ts, y0 = (tile / tiles_x) * ts;
                for (int y = y0; y < std::min(y0 + ts, h); ++y)
                    for (int x = x0; x < std::min(x0 + ts, w); ++x) {
                        const size_t pixel = size_t(y) * size_t(w) + size_t(x);
                        Sampler sampler(settings.seed, pixel, sample_index);
                        const Vec2f jitter = sampler.next2d();
                        const Ray ray = camera.generate(float(x) + jitter.x, float(y) + jitter.y);
                        const Rgb L = estimator.radiance(scene, ray, sampler);
                        if (is_finite(L)) result.film.add(pixel, L);
                        else ++tile_invalid;
                    }
                rays += Scene::rays_traced_by_this_thread() - rays_before;
                invalid += tile_invalid;
                const int done = ++tiles_done;
                if (settings.progress) {
                    const double within = (double(pass) + double(done) / tile_count);
                    double fraction = settings.spp > 0 ? within / settings.spp : 0;
                    if (settings.time_limit > 0) fraction = std::max(fraction, seconds_since_start() / settings.time_limit);
                    progress.update(std::min(fraction, 1.0), uint64_t(within * double(w) * double(h)),
                                    fmt::format("pass {}", pass + 1));
                }
            }
        });
        RenderStats& st = result.stats;
        st.spp = pass + 1;
        st.samples = uint64_t(st.spp) * uint64_t(w) * uint64_t(h);
        st.rays = rays;
        st.invalid_samples = invalid;
        st.seconds = seconds_since_start();
        last_pass_seconds = st.seconds - pass_start;
        if (settings.after_pass) settings.after_pass(result.film, st);
        if (settings.cancel && settings.cancel->load()) {
            st.interrupted = true;
            break;
        }
        // Stop when another pass would end further past the budget than stopping now ends short of it.
        if (settings.time_limit > 0 && st.seconds + 0.5 * last_pass_seconds >= settings.time_limit) break;
    }
    progress.finish();
    return result;
}

}  // namespace pathlab
