// `pathlab_bench bidir`: see bidir_efficiency.hpp. Every method renders the same number of
// iterations; the methods alternate within each repeat, so that the shared machine's load falls
// on all of them alike, and the ratios are taken from the medians.
#include "bidir_efficiency.hpp"

#include <tbb/info.h>

#include <chrono>
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "integrators/photon/vcm.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {

void bidir_efficiency_suite(const BidirEfficiencyOptions& o) {
    const int threads = tbb::info::default_concurrency();
    fmt::print("# Bidirectional methods against pt-mis at {0}x{0}, {1} iterations per render, {2} threads, medians of {3}\n\n", o.size,
               o.iterations, threads, o.repeats);
    fmt::print("MSE per sample = MSE x iterations, against bdpt at {} spp (its noise subtracted); efficiency = 1 / (MSE x seconds), "
               "relative to pt-mis's.\n",
               o.ref_spp);
    for (const std::string& key : o.scenes) {
        const auto scene = Scene::build(load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + key));
        const auto t0 = std::chrono::steady_clock::now();
        const Reference ref = make_reference(*scene, "bdpt", o.size, o.ref_spp);
        const double ref_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        fmt::print("\n## scenes/{} (reference: {:.0f} s)\n", key, ref_seconds);
        for (const std::string& sampler_name : o.samplers) {
            const SamplerKind sampler = sampler_name == "sobol" ? SamplerKind::Sobol : SamplerKind::Independent;
            std::map<std::string, std::vector<double>> seconds, mse, efficiency;
            for (int r = 0; r < o.repeats; ++r)
                for (const std::string& a : o.algorithms) {
                    const RenderResult res = run(*scene, a, o.size, o.iterations, 0, 1000 + uint64_t(r), {}, sampler);
                    const double e = rmse(res.film.mean(), ref);
                    seconds[a].push_back(res.stats.seconds / o.iterations);
                    mse[a].push_back(e * e * o.iterations);
                    efficiency[a].push_back(1 / (e * e * res.stats.seconds));
                }
            fmt::print("\n{} sampler:\n\n| method | s per iteration | MSE per sample | efficiency / {}'s |\n|---|---|---|---|\n", sampler_name,
                       o.algorithms.front());
            const double base = median(efficiency[o.algorithms.front()]);
            for (const std::string& a : o.algorithms)
                fmt::print("| {} | {:.3f} | {:.3g} | {:.2f} |\n", a, median(seconds[a]), median(mse[a]), median(efficiency[a]) / base);
            if (seconds.count("vcm") && seconds.count("bdpt"))
                fmt::print("\nvcm's time per iteration / bdpt's: {:.2f}\n", median(seconds["vcm"]) / median(seconds["bdpt"]));
            std::fflush(stdout);
        }
        // What vcm keeps per light vertex: a merge vertex per photon, a path vertex per light vertex.
        const PerspectiveCamera camera(scene->camera(), o.size, o.size);
        const RenderContext ctx{*scene, camera, o.size, o.size, 5, SamplerKind::Independent, 32};
        Vcm<RgbTransport> vcm({});
        Film film(o.size, o.size);
        vcm.render_passes(ctx, film, 0, 1, {});
        fmt::print("\nvcm's light vertices: {} ({} photons); {:.0f} bytes held per light vertex (a merge vertex is {} bytes, a path "
                   "vertex {})\n",
                   vcm.light_vertex_count(), vcm.photon_count(), double(vcm.memory_bytes()) / double(std::max<size_t>(1, vcm.light_vertex_count())),
                   sizeof(MergeVertex<RgbTransport>), sizeof(PathVertex<RgbTransport>));
        std::fflush(stdout);
    }
}

}  // namespace pathlab::bench
