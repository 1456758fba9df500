// `pathlab_bench lt` (part of `make bench`):
//  1. lt light paths per second next to pt-mis camera paths per second, on the course scenes,
//     measured in interleaved pairs (ratios are medians of per-pair ratios);
//  2. the two deterministic ways of adding splats from many threads, on the splats of real lt
//     passes: per-chunk lists merged in chunk order (what render/pass_image.hpp does) against
//     accumulating 64-bit fixed-point integers with atomic adds (order-independent sums).
#include "light_tracing.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "integrators/bidir/light_tracer.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::bench {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Rate {
    double mpaths = 0, mrays = 0;
};
Rate rate(const Scene& scene, const std::string& algorithm, const LightTracingOptions& o, uint64_t seed) {
    const RenderResult r = run(scene, algorithm, o.size, 0, o.seconds, seed);
    return {double(r.stats.samples) / r.stats.seconds * 1e-6, double(r.stats.rays) / r.stats.seconds * 1e-6};
}

// The splats of one lt pass, chunk by chunk, as the light tracer makes them.
std::vector<std::vector<Splat>> record_pass(const Scene& scene, int size, uint64_t pass) {
    const PerspectiveCamera camera(scene.camera(), size, size);
    const RenderContext ctx{scene, camera, size, size, 17, SamplerKind::Independent, 32};
    const LightTracer<RgbTransport> lt({});
    const size_t paths = ctx.pixel_count(), per_chunk = LightTracer<RgbTransport>::chunk_size(paths);
    const size_t chunks = (paths + per_chunk - 1) / per_chunk;
    std::vector<std::vector<Splat>> out(chunks);
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        SplatList list;
        uint64_t invalid = 0;
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            Sampler sampler(ctx.seed, j, pass);
            lt.trace(ctx, sampler, list, invalid);
        }
        out[c] = list.splats();
    });
    return out;
}

// (a) per-chunk lists, merged in chunk order into the pass image, then the pass into the film.
double time_chunk_lists(const std::vector<std::vector<Splat>>& chunks, PassImage& pass, Film& film) {
    const auto t0 = Clock::now();
    pass.begin(film.pixel_count(), int(chunks.size()));
    tbb::parallel_for(size_t(0), chunks.size(), [&](size_t c) {
        SplatList& list = pass.chunk(int(c));
        for (const Splat& s : chunks[c]) list.add(s.pixel, s.value);
    });
    pass.finish(film);
    return seconds_since(t0);
}

// (b) fixed point: 2^-32 per unit in 64-bit integers, atomic adds from any thread, then
// converted to double for the film.
double time_fixed_point(const std::vector<std::vector<Splat>>& chunks, std::vector<std::atomic<int64_t>>& acc,
                        std::vector<Vec3d>& values, Film& film) {
    constexpr double kScale = 4294967296.0;
    const auto t0 = Clock::now();
    for (auto& a : acc) a.store(0, std::memory_order_relaxed);
    tbb::parallel_for(size_t(0), chunks.size(), [&](size_t c) {
        for (const Splat& s : chunks[c])
            for (int k = 0; k < 3; ++k)
                acc[size_t(s.pixel) * 3 + size_t(k)].fetch_add(int64_t(std::llround(double(s.value[k]) * kScale)),
                                                               std::memory_order_relaxed);
    });
    for (size_t i = 0; i < values.size(); ++i)
        values[i] = Vec3d(double(acc[3 * i].load()) / kScale, double(acc[3 * i + 1].load()) / kScale,
                          double(acc[3 * i + 2].load()) / kScale);
    film.add_pass(values);
    return seconds_since(t0);
}

}  // namespace

void light_tracing_suite(const LightTracingOptions& o) {
    const int threads = std::min(2, tbb::this_task_arena::max_concurrency());
    fmt::print("## lt light paths/s and pt-mis camera paths/s at {0}x{0}, {1} threads (medians of {2} interleaved pairs of "
               "{3} s)\n\n",
               o.size, threads, o.repeats, o.seconds);
    fmt::print("| scene | pt-mis Mpaths/s | lt Mpaths/s | lt / pt-mis | pt-mis rays/path | lt rays/path |\n|---|---|---|---|---|---|\n");
    for (int index : o.scenes) {
        const auto scene = Scene::build(make_builtin_scene(index));
        std::vector<double> pt, lt, ratio, pt_rays, lt_rays;
        for (int k = 0; k < o.repeats; ++k) {
            const Rate a = rate(*scene, "pt-mis", o, 10 + uint64_t(k)), b = rate(*scene, "lt", o, 10 + uint64_t(k));
            pt.push_back(a.mpaths), lt.push_back(b.mpaths), ratio.push_back(b.mpaths / a.mpaths);
            pt_rays.push_back(a.mrays / a.mpaths), lt_rays.push_back(b.mrays / b.mpaths);
        }
        fmt::print("| {} {} | {:.3f} | {:.3f} | {:.2f}x | {:.2f} | {:.2f} |\n", index, builtin_scenes()[size_t(index)].name,
                   median(pt), median(lt), median(ratio), median(pt_rays), median(lt_rays));
        std::fflush(stdout);
    }

    fmt::print("\n## Adding the splats of one lt pass at {0}x{0} ({1} threads, medians of {2})\n\n", o.splat_size, threads,
               o.splat_repeats);
    fmt::print("| scene | splats per pass | per-chunk lists, ms | fixed-point atomics, ms | lists / atomics |\n|---|---|---|---|---|\n");
    for (int index : {3, 7}) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const auto chunks = record_pass(*scene, o.splat_size, 0);
        size_t splats = 0;
        for (const auto& c : chunks) splats += c.size();
        Film film(o.splat_size, o.splat_size);
        PassImage pass;
        std::vector<std::atomic<int64_t>> acc(film.pixel_count() * 3);
        std::vector<Vec3d> values(film.pixel_count());
        std::vector<double> lists, atomics, ratio;
        for (int k = 0; k < o.splat_repeats; ++k) {
            const double a = time_chunk_lists(chunks, pass, film), b = time_fixed_point(chunks, acc, values, film);
            lists.push_back(a * 1e3), atomics.push_back(b * 1e3), ratio.push_back(a / b);
        }
        fmt::print("| {} {} | {} | {:.2f} | {:.2f} | {:.2f} |\n", index, builtin_scenes()[size_t(index)].name, splats,
                   median(lists), median(atomics), median(ratio));
    }
    fmt::print("\nBoth are bit-identical for any thread count. Fixed point also rounds every splat to 2^-32 and\n"
               "overflows past 2^31 per pixel and pass (a splat next to the lens can be that large).\n");
}

}  // namespace pathlab::bench
