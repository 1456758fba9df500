// Efficiency of the course's estimators: RMSE against a high-spp reference at equal spp and at
// equal time on the 8 scenes (`pathlab_bench direct` and `pathlab_bench pt`).
#include "estimator_efficiency.hpp"

#include <fmt/format.h>

#include "bench_common.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::bench {
namespace {

std::vector<int> parse_scenes(const std::string& list) {
    std::vector<int> out;
    size_t start = 0;
    while (start < list.size()) {
        const size_t comma = std::min(list.find(',', start), list.size());
        out.push_back(std::stoi(list.substr(start, comma - start)));
        start = comma + 1;
    }
    return out;
}

}  // namespace

void efficiency_table(const EfficiencyOptions& o, const std::vector<std::string>& algorithms,
                      const std::string& reference_algorithm) {
    fmt::print("resolution {0}x{0}; reference: {1} at {2} spp; equal spp: {3}; equal time: {4} s; medians of {5} runs\n\n",
               o.size, reference_algorithm, o.ref_spp, o.spp, o.seconds, o.repeats);
    fmt::print("| scene | estimator | RMSE @ {} spp | RMSE @ {} s | spp in {} s | Msamples/s | Mrays/s |\n", o.spp, o.seconds,
               o.seconds);
    fmt::print("|---|---|---|---|---|---|---|\n");
    for (int index : parse_scenes(o.scenes)) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const Reference ref = make_reference(*scene, reference_algorithm, o.size, o.ref_spp);
        for (const std::string& a : algorithms) {
            const double equal_spp = rmse(run(*scene, a, o.size, o.spp, 0, 1).film.mean(), ref);
            std::vector<double> err, spp, msps, mrps;
            for (int k = 0; k < o.repeats; ++k) {
                const RenderResult r = run(*scene, a, o.size, 0, o.seconds, 100 + uint64_t(k));
                err.push_back(rmse(r.film.mean(), ref));
                spp.push_back(r.stats.spp);
                msps.push_back(double(r.stats.samples) / r.stats.seconds * 1e-6);
                mrps.push_back(double(r.stats.rays) / r.stats.seconds * 1e-6);
            }
            fmt::print("| {} {} | {} | {:.4g} | {:.4g} | {:.0f} | {:.2f} | {:.2f} |\n", index,
                       builtin_scenes()[size_t(index)].name, a, equal_spp, median(err), median(spp), median(msps),
                       median(mrps));
            std::fflush(stdout);
        }
    }
}

}  // namespace pathlab::bench
