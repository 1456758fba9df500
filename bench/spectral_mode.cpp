#include "spectral_mode.hpp"

#include <chrono>
#include <memory>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "job/render_job.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {

void spectral_mode_suite(const SpectralModeOptions& o) {
    fmt::print("spectral mode against RGB mode: {}x{}, {} spp per render, medians of {} interleaved rounds\n", o.size, o.size, o.spp,
               o.repeats);
    fmt::print("{:<18} {:<10} {:>14} {:>14} {:>8}\n", "scene", "algorithm", "RGB ns/sample", "spectral ns/s.", "ratio");
    std::vector<SceneChoice> choices;
    for (int index : o.scenes) choices.push_back(builtin_scene_choice(index));
    for (const std::string& file : o.scene_files) choices.push_back(scene_choice_of(load_scene_file(file)));
    for (const SceneChoice& choice : choices) {
        const std::shared_ptr<const Scene> scene = Scene::build(choice.description);
        for (const std::string& algorithm : o.algorithms) {
            std::vector<double> rgb_ns, spectral_ns, ratios;
            for (int round = 0; round < o.repeats; ++round) {
                double ns[2];
                for (int mode = 0; mode < 2; ++mode) {
                    JobRequest request;
                    request.algorithm = algorithm;
                    request.spp = uint64_t(o.spp);
                    request.width = request.height = o.size;
                    request.seed = uint64_t(round + 1);
                    request.spectral = mode == 1;
                    RenderJob job(choice, request, scene);
                    const auto start = std::chrono::steady_clock::now();
                    const RenderResult r = job.run();
                    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                    ns[mode] = seconds * 1e9 / double(r.stats.samples);
                }
                rgb_ns.push_back(ns[0]);
                spectral_ns.push_back(ns[1]);
                ratios.push_back(ns[1] / ns[0]);
            }
            fmt::print("{:<18} {:<10} {:>14.0f} {:>14.0f} {:>8.3f}\n", choice.name, algorithm, median(rgb_ns), median(spectral_ns),
                       median(ratios));
        }
    }
}

}  // namespace pathlab::bench
