// `pathlab_bench bdpt` (part of `make bench`):
//  1. equal-time RMSE of bdpt and pt-mis on the 8 course scenes and the shipped scene files
//     (lampshade, caustic, smallvcm-box), against a long bdpt reference whose own noise is
//     subtracted (bench_common.hpp), in interleaved pairs of renders; the MSE ratio is split
//     into its two causes: variance per sample (MSE x spp) and time per sample;
//  2. bdpt samples per second (each one camera and one light subpath, all their connections)
//     next to pt-mis paths per second, on SmallVCM's kind of scene and the lampshade;
//  3. variance per sample by path length (both restricted to one length at a time), which
//     says where bdpt's extra strategies pay and where they cost.
#include "bidirectional.hpp"

#include <tbb/task_arena.h>

#include <cstdio>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "job/scene_choice.hpp"
#include "scene/builtin_scenes.hpp"
#include "integrators/integrators.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {
namespace {

SceneDescription scene_of(const std::string& key) {
    if (looks_like_scene_file(key)) return load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + key);
    return make_builtin_scene(std::stoi(key));
}

std::string name_of(const std::string& key) {
    return looks_like_scene_file(key) ? key : fmt::format("{} {}", key, builtin_scenes()[size_t(std::stoi(key))].name);
}

struct Timed {
    double rmse = 0, spp = 0, seconds = 0, mpaths = 0, rays_per_path = 0;
};

Timed timed(const Scene& scene, const std::string& algorithm, int size, double seconds, uint64_t seed, const Reference* ref) {
    const RenderResult r = run(scene, algorithm, size, 0, seconds, seed);
    Timed t;
    t.spp = double(r.stats.spp);
    t.seconds = r.stats.seconds;
    t.mpaths = double(r.stats.samples) / r.stats.seconds * 1e-6;
    t.rays_per_path = double(r.stats.rays) / double(r.stats.samples);
    if (ref) t.rmse = rmse(r.film.mean(), *ref);
    return t;
}

// Mean over pixels and channels of the variance of one sample (squared standard error x spp).
double variance_per_sample(const Scene& scene, const std::string& algorithm, int length, int size, uint64_t spp) {
    IntegratorOptions options;
    options.only_length = length;
    const std::unique_ptr<Integrator> integrator = find_integrator(algorithm)->make(options);
    RenderSettings rs;
    rs.width = rs.height = size, rs.spp = spp, rs.seed = 31;
    const Image se = render(scene, *integrator, rs).film.standard_error();
    double v = 0;
    for (size_t i = 0; i < se.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) v += double(se[i][c]) * se[i][c];
    return v * double(spp) / double(3 * se.pixel_count());
}

}  // namespace

void bidirectional_suite(const BidirectionalOptions& o) {
    const int threads = std::min(2, tbb::this_task_arena::max_concurrency());
    fmt::print("## Equal time: bdpt against pt-mis at {0}x{0}, {1} s per render, {2} threads (medians of {3} interleaved "
               "pairs; reference: bdpt at {4} spp, its noise subtracted)\n\n",
               o.size, o.seconds, threads, o.repeats, o.ref_spp);
    fmt::print("MSE ratio = pt-mis MSE / bdpt MSE at equal time (> 1: bdpt wins) = variance ratio / time ratio, where\n"
               "variance ratio = pt-mis / bdpt variance per sample (MSE x spp) and time ratio = bdpt / pt-mis time per sample.\n\n");
    fmt::print("| scene | pt-mis RMSE | bdpt RMSE | pt-mis spp | bdpt spp | MSE ratio | variance ratio | time ratio | winner |\n"
               "|---|---|---|---|---|---|---|---|---|\n");
    for (const std::string& key : o.scenes) {
        const auto scene = Scene::build(scene_of(key));
        const Reference ref = make_reference(*scene, "bdpt", o.size, o.ref_spp);
        std::vector<double> pt_rmse, bd_rmse, pt_spp, bd_spp, mse_ratio, var_ratio, time_ratio;
        for (int k = 0; k < o.repeats; ++k) {
            const Timed a = timed(*scene, "pt-mis", o.size, o.seconds, 100 + uint64_t(k), &ref);
            const Timed b = timed(*scene, "bdpt", o.size, o.seconds, 200 + uint64_t(k), &ref);
            pt_rmse.push_back(a.rmse), bd_rmse.push_back(b.rmse), pt_spp.push_back(a.spp), bd_spp.push_back(b.spp);
            // Efficiency is 1 / (MSE x time): the ratio corrects for renders ending a little apart.
            mse_ratio.push_back((a.rmse * a.rmse * a.seconds) / (b.rmse * b.rmse * b.seconds));
            var_ratio.push_back((a.rmse * a.rmse * a.spp) / (b.rmse * b.rmse * b.spp));
            time_ratio.push_back((b.seconds / b.spp) / (a.seconds / a.spp));
        }
        const double m = median(mse_ratio);
        fmt::print("| {} | {:.4f} | {:.4f} | {:.0f} | {:.0f} | {:.2f} | {:.2f} | {:.2f} | {} |\n", name_of(key), median(pt_rmse),
                   median(bd_rmse), median(pt_spp), median(bd_spp), m, median(var_ratio), median(time_ratio),
                   m > 1.1 ? "bdpt" : m < 1 / 1.1 ? "pt-mis" : "even");
        std::fflush(stdout);
    }

    fmt::print("\n## Throughput at {0}x{0}, {1} threads (medians of {2} interleaved pairs of {3} s)\n\n", o.throughput_size,
               threads, o.repeats, o.throughput_seconds);
    fmt::print("A bdpt sample is one camera subpath, one light subpath and all their connections.\n\n");
    fmt::print("| scene | pt-mis Mpaths/s | bdpt Msamples/s | pt-mis / bdpt | pt-mis rays/path | bdpt rays/sample |\n"
               "|---|---|---|---|---|---|\n");
    for (const std::string key : {"smallvcm-box.xml", "lampshade.xml", "4"}) {
        const auto scene = Scene::build(scene_of(key));
        std::vector<double> pt, bd, ratio, pt_rays, bd_rays;
        for (int k = 0; k < o.repeats; ++k) {
            const Timed a = timed(*scene, "pt-mis", o.throughput_size, o.throughput_seconds, 10 + uint64_t(k), nullptr);
            const Timed b = timed(*scene, "bdpt", o.throughput_size, o.throughput_seconds, 10 + uint64_t(k), nullptr);
            pt.push_back(a.mpaths), bd.push_back(b.mpaths), ratio.push_back(a.mpaths / b.mpaths);
            pt_rays.push_back(a.rays_per_path), bd_rays.push_back(b.rays_per_path);
        }
        fmt::print("| {} | {:.3f} | {:.3f} | {:.2f} | {:.2f} | {:.2f} |\n", name_of(key), median(pt), median(bd), median(ratio),
                   median(pt_rays), median(bd_rays));
        std::fflush(stdout);
    }

    constexpr int kLengthSize = 16;
    constexpr uint64_t kLengthSpp = 2048;
    fmt::print("\n## Variance per sample by path length at {0}x{0}, {1} spp: pt-mis / bdpt (> 1: bdpt's strategies help)\n\n",
               kLengthSize, kLengthSpp);
    fmt::print("| scene | 0 bounces | 1 | 2 | 3 | 4 |\n|---|---|---|---|---|---|\n");
    for (const std::string key : {"2", "4", "lampshade.xml", "caustic.xml"}) {
        const auto scene = Scene::build(scene_of(key));
        std::string row = "| " + name_of(key);
        for (int n = 0; n <= 4; ++n) {
            const double a = variance_per_sample(*scene, "pt-mis", n, kLengthSize, kLengthSpp);
            const double b = variance_per_sample(*scene, "bdpt", n, kLengthSize, kLengthSpp);
            row += b > 0 ? fmt::format(" | {:.2f}", a / b) : " | -";
        }
        fmt::print("{} |\n", row);
        std::fflush(stdout);
    }
}

}  // namespace pathlab::bench
