// `pathlab_bench diff` (see differentiable.hpp). CPU time of the whole process rather than wall
// time: on the shared machine it counts the work, not the waits.
#include "differentiable.hpp"

#include <sys/resource.h>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "diff/loss.hpp"
#include "diff/path_replay.hpp"
#include "instrument/allocation_counter.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {
namespace {

double process_cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

template <typename F>
double cpu_seconds(F&& f) {
    const double t0 = process_cpu_seconds();
    f();
    return process_cpu_seconds() - t0;
}

std::vector<std::string> all_names(const SceneDescription& d) {
    std::vector<std::string> names;
    for (const SceneParameter& p : scene_parameters(d)) names.push_back(p.name);
    return names;
}

// Heap allocations (all threads) of one gradient at size x size, spp, and max depth (-1: unlimited,
// Russian roulette from depth 3).
uint64_t gradient_allocations(const Scene& scene, const ParameterSet& set, const Image& adjoint, int size, int spp, int depth) {
    DiffSettings s;
    s.width = s.height = size;
    s.spp = spp;
    s.max_depth = depth;
    s.rr_depth = depth < 0 ? 3 : -1;
    const uint64_t before = allocations_by_all_threads();
    gradient(scene, set, s, adjoint);
    return allocations_by_all_threads() - before;
}

std::string depth_label(int depth) { return depth < 0 ? std::string("unlimited (RR)") : std::to_string(depth); }

}  // namespace

void differentiable_suite(const DifferentiableOptions& o) {
    fmt::print("## Differentiable rendering: cost of a gradient\n\n");
    fmt::print("CPU seconds of the process, median of {} interleaved rounds, {}x{} pixels, {} spp, every parameter of the "
               "scene bound; ratios to the primal render (pt-mis's estimator; volpath's in a medium) of the same spp.\n\n",
               o.repeats, o.size, o.size, o.spp);
    fmt::print("| scene | parameters (floats) | pt-mis or volpath render (s) | primal (s) | gradient (s) | gradient / primal | iteration / primal |\n");
    fmt::print("|---|---|---|---|---|---|---|\n");
    // A row per scene: the course scenes by index, the texture example (its texels bound too), the fog.
    struct Row {
        std::string name;
        SceneDescription d;
        std::string integrator = "pt-mis";
    };
    std::vector<Row> rows;
    for (int index : o.scenes) rows.push_back({fmt::format("{} {}", index, builtin_scenes()[size_t(index)].name), make_builtin_scene(index)});
    if (!o.texture_scene.empty()) {
        SceneDescription d = load_scene_file(o.texture_scene);
        int texels = 0;
        for (const SceneParameter& p : scene_parameters(d)) texels += p.is_texels() ? p.size / 3 : 0;
        rows.push_back({fmt::format("diff-texture ({} texels)", texels), std::move(d)});
    }
    if (!o.media_scene.empty()) rows.push_back({"fog-box (homogeneous medium)", load_scene_file(o.media_scene), "volpath"});
    for (const Row& row : rows) {
        const SceneDescription& d = row.d;
        const ParameterSet set = ParameterSet::choose(d, all_names(d));
        const auto scene = Scene::build(d);
        DiffSettings s;
        s.width = s.height = o.size;
        s.spp = o.spp;
        const Image target = render_primal(*scene, s);  // any image: the adjoint's values do not change the cost
        const Image adjoint = loss_adjoint(Image(o.size, o.size, Rgb(0.5f)), target, Loss{});
        std::vector<double> pt, primal, grad, ratio_g, ratio_it;
        for (int r = 0; r < o.repeats; ++r) {
            pt.push_back(cpu_seconds([&] { run(*scene, row.integrator, o.size, o.spp, 0, 1234); }));
            const double p = cpu_seconds([&] { render_primal(*scene, s); });
            const double g = cpu_seconds([&] { gradient(*scene, set, s, adjoint); });
            primal.push_back(p), grad.push_back(g);
            ratio_g.push_back(g / p), ratio_it.push_back((p + g) / p);
        }
        fmt::print("| {} | {} ({} floats) | {:.3f} | {:.3f} | {:.3f} | {:.2f} | {:.2f} |\n", row.name, set.params.size(), set.size,
                   median(pt), median(primal), median(grad), median(ratio_g), median(ratio_it));
    }

    fmt::print("\n## Differentiable rendering: memory of a gradient against spp and depth\n\n");
    fmt::print("Heap allocations (all threads) during one gradient evaluation of scene 3 at {}x{}, every parameter bound: "
               "no per-path tape, so the count does not grow with spp or path length.\n\n",
               o.size, o.size);
    fmt::print("| spp | max depth | heap allocations | paths' vertices (approx.) | peak RSS (MiB) |\n|---|---|---|---|---|\n");
    const SceneDescription d = make_builtin_scene(3);
    const ParameterSet set = ParameterSet::choose(d, all_names(d));
    const auto scene = Scene::build(d);
    const Image adjoint(o.size, o.size, Rgb(1.0f));
    for (const auto& [spp, depth] : std::vector<std::pair<int, int>>{{1, 1}, {4, 1}, {16, 1}, {64, 1}, {16, 4}, {16, 16}, {16, -1}}) {
        const uint64_t allocations = gradient_allocations(*scene, set, adjoint, o.size, spp, depth);
        const double vertices = double(o.size) * o.size * spp * (depth < 0 ? 5.0 : double(depth));
        fmt::print("| {} | {} | {} | {:.2g} | {:.0f} |\n", spp, depth_label(depth), allocations, vertices, peak_rss_mib());
    }
    if (!o.texture_scene.empty()) {
        // The texels: one gradient buffer of the texture's size per sum in flight, whatever spp and depth.
        const SceneDescription t = load_scene_file(o.texture_scene);
        const ParameterSet ts = ParameterSet::choose(t, all_names(t));
        const auto tscene = Scene::build(t);
        fmt::print("\nThe same for scenes/diff-texture.xml with its {} floats bound (the texels among them):\n\n", ts.size);
        fmt::print("| spp | max depth | heap allocations | peak RSS (MiB) |\n|---|---|---|---|\n");
        for (const auto& [spp, depth] : std::vector<std::pair<int, int>>{{1, 1}, {16, 1}, {64, 1}, {16, 16}, {16, -1}}) {
            const uint64_t allocations = gradient_allocations(*tscene, ts, adjoint, o.size, spp, depth);
            fmt::print("| {} | {} | {} | {:.0f} |\n", spp, depth_label(depth), allocations, peak_rss_mib());
        }
    }
    fmt::print("\n");
}

}  // namespace pathlab::bench
