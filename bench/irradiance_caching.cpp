// `pathlab_bench ic` (part of `make bench`): ic against pt-mis and bdpt at equal time (1, 4 and
// 16 s by default) on the diffuse course scenes against a long pt-mis reference (its noise
// subtracted), in interleaved rounds; ic's records and cache build time; and its bias, left when
// the noise is gone: the RMS difference of a long ic render from the reference with both
// images' noise subtracted.
#include "irradiance_caching.hpp"

#include <tbb/task_arena.h>

#include <cstdio>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::bench {
namespace {

double statistic(const RenderStats& s, const std::string& name) {
    for (const IntegratorStatistic& x : s.integrator)
        if (x.name == name) return x.value;
    return 0;
}

}  // namespace

void irradiance_caching_suite(const IrradianceCachingOptions& o) {
    const int threads = std::min(2, tbb::this_task_arena::max_concurrency());
    const std::vector<std::string> algorithms{"pt-mis", "bdpt", "ic"};
    fmt::print("## ic at equal time, {0}x{0} ({1} threads, medians of {2} rounds; reference: pt-mis at {3} spp, its noise subtracted)\n\n",
               o.size, threads, o.repeats, o.ref_spp);
    fmt::print("| scene | budget s | pt-mis RMSE | bdpt RMSE | ic RMSE | ic / pt-mis MSE | ic records | ic cache s |\n"
               "|---|---|---|---|---|---|---|---|\n");
    for (const int index : o.scenes) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const Reference ref = make_reference(*scene, "pt-mis", o.size, o.ref_spp);
        for (const double budget : o.budgets) {
            std::vector<std::vector<double>> errors(algorithms.size());
            std::vector<double> records, cache_seconds;
            for (int k = 0; k < o.repeats; ++k)
                for (size_t a = 0; a < algorithms.size(); ++a) {
                    const RenderResult r = run(*scene, algorithms[a], o.size, 0, budget, 500 + uint64_t(k));
                    errors[a].push_back(rmse(r.film.mean(), ref));
                    if (algorithms[a] == "ic") {
                        records.push_back(statistic(r.stats, "records"));
                        cache_seconds.push_back(statistic(r.stats, "cache_seconds"));
                    }
                }
            const double pt = median(errors[0]), ic = median(errors[2]);
            fmt::print("| {} | {:g} | {:.4f} | {:.4f} | {:.4f} | {:.2f} | {:.0f} | {:.2f} |\n", index, budget, pt, median(errors[1]), ic,
                       pt > 0 ? ic * ic / (pt * pt) : 0.0, median(records), median(cache_seconds));
            std::fflush(stdout);
        }
        // The bias left: a long ic render (its noise and the reference's subtracted).
        const RenderResult r = run(*scene, "ic", o.size, o.ref_spp / 2, 0, 77);
        const Image se = r.film.standard_error();
        double sum = 0;
        for (size_t i = 0; i < se.pixel_count(); ++i)
            for (int c = 0; c < 3; ++c) {
                const double d = double(r.film.mean()[i][c]) - ref.mean[i][c];
                sum += d * d - double(se[i][c]) * se[i][c];
            }
        const double bias = std::sqrt(std::max(0.0, sum / double(3 * se.pixel_count()) - ref.noise_mse));
        fmt::print("| {} | bias at {} spp | | | {:.4f} | | | |\n", index, o.ref_spp / 2, bias);
        std::fflush(stdout);
    }
}

}  // namespace pathlab::bench
