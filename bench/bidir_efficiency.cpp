// `pathlab_bench bidir`: see bidir_efficiency.hpp. Every method renders the same number of
// iterations; the methods alternate within each repeat, so that the shared machine's load falls
// on all of them alike, and the ratios are taken from the medians.
#include "bidir_efficiency.hpp"

#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "image/image_io.hpp"
#include "integrators/photon/vcm.hpp"
#include "judge/specular_mask.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {
namespace {

// Light tracing (lt, and its settings "lt:...") connects no path through a Dirac surface seen
// first: those pixels are black by design (docs/estimators.md#light-tracing).
bool sees_no_dirac_surface_first(const std::string& algorithm) { return algorithm == "lt" || algorithm.rfind("lt:", 0) == 0; }

// Images rendered elsewhere ("LABEL:ITERATIONS:SECONDS=FILE"), judged as the methods below are.
void judge_images(const std::vector<std::string>& specs, const Reference& ref) {
    fmt::print("\nImages from elsewhere:\n\n| image | iterations | s per iteration | MSE per sample | 1 / (MSE x s) |\n|---|---|---|---|---|\n");
    for (const std::string& spec : specs) {
        const size_t eq = spec.find('='), c1 = spec.find(':'), c2 = spec.find(':', c1 + 1);
        if (eq == std::string::npos || c2 == std::string::npos || c2 > eq)
            throw std::runtime_error(fmt::format("--judge {}: expected LABEL:ITERATIONS:SECONDS=FILE", spec));
        const std::string label = spec.substr(0, c1), file = spec.substr(eq + 1);
        const int iterations = std::stoi(spec.substr(c1 + 1, c2 - c1 - 1));
        const double seconds = std::stod(spec.substr(c2 + 1, eq - c2 - 1));
        const Image img = read_image(file);
        if (img.width() != ref.mean.width() || img.height() != ref.mean.height())
            throw std::runtime_error(fmt::format("--judge {}: {}x{}, the reference is {}x{}", file, img.width(), img.height(),
                                                 ref.mean.width(), ref.mean.height()));
        const double e = rmse(img, ref);
        fmt::print("| {} | {} | {:.3f} | {:.3g} | {:.3g} |\n", label, iterations, seconds / iterations, e * e * iterations,
                   1 / (e * e * seconds));
    }
}

}  // namespace

void bidir_efficiency_suite(const BidirEfficiencyOptions& o) {
    const int threads = tbb::info::default_concurrency();
    fmt::print("# Bidirectional methods against {5} at {0}x{0}, {1} iterations per render, {2} threads, medians of {3}{4}\n\n", o.size,
               o.iterations, threads, o.repeats, o.max_depth > 0 ? fmt::format(", at most {} bounces", o.max_depth) : "",
               o.algorithms.front());
    fmt::print("MSE per sample = MSE x iterations, against bdpt at {} spp (its noise subtracted); efficiency = 1 / (MSE x seconds), "
               "relative to {}'s.\n",
               o.ref_spp, o.algorithms.front());
    for (const std::string& key : o.scenes) {
        const auto scene = Scene::build(load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + key));
        const auto t0 = std::chrono::steady_clock::now();
        const std::string depth = o.max_depth > 0 ? fmt::format(":max_depth={}", o.max_depth) : "";
        const Reference ref = make_reference(*scene, "bdpt" + depth, o.size, o.ref_spp);
        const double ref_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        fmt::print("\n## scenes/{} (reference: {:.0f} s)\n", key, ref_seconds);
        // Pixels whose first surface is a Dirac one: lt's image is incomplete there.
        const bool any_lt = std::any_of(o.algorithms.begin(), o.algorithms.end(), sees_no_dirac_surface_first);
        const size_t dirac_pixels = any_lt ? count_marked(specular_first_vertex_mask(*scene, o.size, o.size, 4, /*dilate=*/false)) : 0;
        if (key == o.scenes.front() && !o.judge.empty()) judge_images(o.judge, ref);
        for (const std::string& sampler_name : o.samplers) {
            const SamplerKind sampler = sampler_name == "sobol" ? SamplerKind::Sobol : SamplerKind::Independent;
            std::map<std::string, std::vector<double>> seconds, mse, efficiency;
            for (int r = 0; r < o.repeats; ++r)
                for (const std::string& a : o.algorithms) {
                    const RenderResult res = run(*scene, a + depth, o.size, o.iterations, 0, 1000 + uint64_t(r), {}, sampler);
                    const double e = rmse(res.film.mean(), ref);
                    seconds[a].push_back(res.stats.seconds / o.iterations);
                    mse[a].push_back(e * e * o.iterations);
                    efficiency[a].push_back(1 / (e * e * res.stats.seconds));
                }
            if (!o.judge.empty() && key == o.scenes.front()) {
                fmt::print("\n{} sampler, absolute:\n\n| method | MSE per sample | 1 / (MSE x s) |\n|---|---|---|\n", sampler_name);
                for (const std::string& a : o.algorithms)
                    fmt::print("| {} | {:.3g} | {:.3g} |\n", a, median(mse[a]), median(efficiency[a]));
            }
            fmt::print("\n{} sampler:\n\n| method | s per iteration | MSE per sample | efficiency / {}'s |\n|---|---|---|---|\n", sampler_name,
                       o.algorithms.front());
            const double base = median(efficiency[o.algorithms.front()]);
            bool incomplete = false;
            for (const std::string& a : o.algorithms) {
                const bool blind = dirac_pixels > 0 && sees_no_dirac_surface_first(a);
                incomplete |= blind;
                fmt::print("| {}{} | {:.3f} | {:.3g} | {:.2f} |\n", a, blind ? " (incomplete)" : "", median(seconds[a]), median(mse[a]),
                           median(efficiency[a]) / base);
            }
            if (incomplete)
                fmt::print("\n(incomplete): {} of {} pixels ({:.1f}%) see a Dirac surface first, which light tracing leaves black by "
                           "design; its MSE includes that bias, which outgrows its noise as the iterations grow.\n",
                           dirac_pixels, size_t(o.size) * size_t(o.size), 100.0 * double(dirac_pixels) / (double(o.size) * o.size));
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
