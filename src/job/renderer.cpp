#include "job/renderer.hpp"

#include <chrono>
#include <fstream>
#include <new>
#include <stdexcept>

#include <fmt/format.h>

#include "render/progress.hpp"

namespace pathlab {
namespace {

void resolve_size(const Scene& scene, const RenderSettings& s, int& w, int& h) {
    w = s.width > 0 ? s.width : scene.default_width();
    h = s.height > 0 ? s.height : scene.default_height();
    if (w <= 0 || h <= 0 || s.width < 0 || s.height < 0)
        throw std::invalid_argument(fmt::format("resolution must be positive, got {}x{}", w, h));
}

// Memory this machine can still give (MemAvailable), or 0 when unknown.
uint64_t available_memory() {
    std::ifstream in("/proc/meminfo");
    std::string key;
    uint64_t kib = 0;
    std::string unit;
    while (in >> key >> kib >> unit)
        if (key == "MemAvailable:") return kib * 1024;
    return 0;
}

// A film of w x h pixels, or a FilmTooLarge saying how much memory it needs.
Film make_film(int w, int h) {
    const uint64_t pixels = uint64_t(w) * uint64_t(h), bytes = pixels * kRenderBytesPerPixel;
    const uint64_t available = available_memory();
    const auto gib = [](uint64_t b) { return double(b) / double(uint64_t(1) << 30); };
    if (available > 0 && bytes > available)
        throw FilmTooLarge(fmt::format("a {}x{} render needs {:.1f} GiB of memory ({} bytes per pixel for the film and its "
                                       "images), but only {:.1f} GiB is available",
                                       w, h, gib(bytes), kRenderBytesPerPixel, gib(available)));
    try {
        return Film(w, h);
    } catch (const std::bad_alloc&) {
        throw FilmTooLarge(fmt::format("a {}x{} render needs {:.1f} GiB of memory ({} bytes per pixel for the film and its "
                                       "images), more than could be allocated",
                                       w, h, gib(bytes), kRenderBytesPerPixel));
    }
}

}  // namespace

RenderResult render(const Scene& scene, Integrator& integrator, const RenderSettings& settings) {
    int w, h;
    resolve_size(scene, settings, w, h);
    RenderResult result{make_film(w, h), {}};
    result.stats = render_into(scene, integrator, settings, result.film);
    return result;
}

RenderStats render_into(const Scene& scene, Integrator& integrator, const RenderSettings& settings, Film& film) {
    int w, h;
    resolve_size(scene, settings, w, h);
    if (film.width() != w || film.height() != h)
        throw std::invalid_argument(fmt::format("the film is {}x{}, the render {}x{}", film.width(), film.height(), w, h));
    if (settings.spp <= 0 && settings.time_limit <= 0)
        throw std::invalid_argument("a render needs a positive sample count or time limit");

    const PerspectiveCamera camera(scene.camera(), w, h);
    const PixelFilter filter(scene.description().filter, w, h);
    const RenderContext ctx{scene, camera, w, h, settings.seed, settings.sampler, settings.tile_size, &filter};
    Progress progress(settings.progress);
    const auto start = std::chrono::steady_clock::now();
    const auto seconds_since_start = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    PassProgress on_prepare;
    if (settings.progress) on_prepare = [&](double fraction) { progress.update(0.0, 0, fmt::format("preparing: {:.0f}%", 100 * fraction)); };
    integrator.prepare(ctx, on_prepare);

    RenderStats st;
    uint64_t done = 0, batch = 1;
    while (settings.spp <= 0 || done < settings.spp) {
        const uint64_t passes = settings.spp > 0 ? std::min(batch, settings.spp - done) : batch;
        const double batch_start = seconds_since_start();
        PassProgress on_progress;
        if (settings.progress)
            on_progress = [&](double fraction_of_batch) {
                const double within = double(done) + double(passes) * fraction_of_batch;
                double fraction = settings.spp > 0 ? within / double(settings.spp) : 0;
                if (settings.time_limit > 0) fraction = std::max(fraction, seconds_since_start() / settings.time_limit);
                progress.update(std::min(fraction, 1.0), uint64_t(within * double(w) * double(h)), fmt::format("{} spp", done));
            };
        const PassCounters c = integrator.render_passes(ctx, film, settings.first_sample + done, int(passes), on_progress);
        done += passes;
        st.spp = done;
        st.samples = done * uint64_t(w) * uint64_t(h);
        st.rays += c.rays;
        st.invalid_samples += c.invalid_samples;
        st.seconds = seconds_since_start();
        const double batch_seconds = st.seconds - batch_start;
        if (settings.after_pass) settings.after_pass(film, st);
        if (settings.cancel && settings.cancel->load()) {
            st.interrupted = true;
            break;
        }
        // Stop when another batch would end further past the budget than stopping now ends short of it.
        if (settings.time_limit > 0) {
            const double per_pass = batch_seconds / double(passes);
            const double left = settings.time_limit - st.seconds;
            if (left <= 0.5 * per_pass) break;
            batch = std::max<uint64_t>(1, std::min<uint64_t>(batch, uint64_t(left / per_pass)));
        }
        if (batch_seconds < 0.05 && batch < (1u << 20)) batch *= 2;
    }
    progress.finish();
    integrator.finish(ctx);
    st.integrator = integrator.statistics();
    return st;
}

}  // namespace pathlab
