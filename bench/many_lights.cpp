// `pathlab_bench many-lights` (part of `make bench`; docs/lights.md quotes it):
//  1. equal time: each scene and algorithm rendered for `seconds` with every light sampler (ris with
//     its default candidates), in
//     interleaved rounds; the MSE against a reference (bvh at ref_spp, another seed, its own
//     noise subtracted), the median over the rounds, and power's MSE over each sampler's
//     (above 1: better than power at equal time);
//  2. the light BVH of scenes/many-lights.xml: build time (median of 9) and bytes per 1000 lights.
#include "many_lights.hpp"

#include <chrono>
#include <map>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "job/scene_choice.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {

void many_lights_suite(const ManyLightsOptions& o) {
    // The samplers compared: every kind, and bvh with adaptive splitting (--light-split).
    struct Sampler {
        std::string name;
        LightSamplerKind kind;
        float split;
    };
    const std::vector<Sampler> samplers = {{"uniform", LightSamplerKind::Uniform, 0},
                                           {"power", LightSamplerKind::Power, 0},
                                           {"bvh", LightSamplerKind::Bvh, 0},
                                           {fmt::format("bvh split {:g}", o.split), LightSamplerKind::Bvh, o.split},
                                           {"ris", LightSamplerKind::Ris, 0}};
    const size_t kPower = 1, kBvh = 2;
    std::vector<std::pair<std::string, SceneDescription>> scenes;
    for (const std::string& f : o.scene_files) scenes.emplace_back(f, load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + f));
    for (const int i : o.scenes) scenes.emplace_back(fmt::format("{} {}", i, builtin_scene_choice(i).name), make_builtin_scene(i));

    fmt::print("## Light samplers at equal time ({}x{}, {} s per render, median of {} rounds; reference bvh at {} spp; ris with {} "
               "candidates)\n\n",
               o.size, o.size, o.seconds, o.repeats, o.ref_spp, kDefaultRisCandidates);
    std::string head = "| scene | lights | algorithm |", rule = "|---|---|---|";
    for (const Sampler& k : samplers) head += fmt::format(" MSE {} |", k.name), rule += "---|";
    for (size_t k = 0; k < samplers.size(); ++k)
        if (k != kPower) head += fmt::format(" power/{} |", samplers[k].name), rule += "---|";
    for (const Sampler& k : samplers) head += fmt::format(" spp {} |", k.name), rule += "---|";
    fmt::print("{}\n{}\n", head, rule);
    for (auto& [name, desc] : scenes) {
        std::vector<std::unique_ptr<Scene>> built;
        for (const Sampler& k : samplers) {
            SceneDescription d = desc;
            d.light_sampler = k.kind;
            d.light_split = k.split;
            built.push_back(Scene::build(d));
        }
        for (const std::string& algorithm : o.algorithms) {
            const Reference ref = make_reference(*built[kBvh], algorithm, o.size, o.ref_spp);
            std::vector<std::vector<double>> mse(samplers.size()), spp(samplers.size());
            for (int round = 0; round < o.repeats; ++round)
                for (size_t k = 0; k < samplers.size(); ++k) {
                    const RenderResult r = run(*built[k], algorithm, o.size, 0, o.seconds, uint64_t(1000 + round));
                    const double e = rmse(r.film.mean(), ref);
                    mse[k].push_back(e * e);
                    spp[k].push_back(double(r.stats.spp));
                }
            std::string row = fmt::format("| {} | {} | {} |", name, built[kPower]->lights().size(), algorithm);
            const double p = median(mse[kPower]);
            for (size_t k = 0; k < samplers.size(); ++k) row += fmt::format(" {:.3g} |", median(mse[k]));
            for (size_t k = 0; k < samplers.size(); ++k)
                if (k != kPower) row += fmt::format(" {:.2f} |", p / median(mse[k]));
            for (size_t k = 0; k < samplers.size(); ++k) row += fmt::format(" {:.0f} |", median(spp[k]));
            fmt::print("{}\n", row);
            std::fflush(stdout);
        }
    }

    const auto scene = Scene::build(load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/many-lights.xml"));
    std::vector<double> ms;
    size_t bytes = 0, nodes = 0;
    for (int i = 0; i < 9; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const LightSampler s(scene->lights(), scene->scene_sphere(), LightSamplerKind::Bvh);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        bytes = s.bytes(), nodes = s.nodes();
    }
    const double per_k = 1000.0 / double(scene->lights().size());
    fmt::print("\n## Light BVH of many-lights.xml: {} lights, {} nodes\n\nbuild {:.2f} ms ({:.3f} ms per 1000 lights), {:.1f} KiB "
               "({:.1f} KiB per 1000 lights)\n\n",
               scene->lights().size(), nodes, median(ms), median(ms) * per_k, double(bytes) / 1024, double(bytes) / 1024 * per_k);
}

}  // namespace pathlab::bench
