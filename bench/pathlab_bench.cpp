// pathlab benchmarks (not tests): efficiency of the estimators on the 8 course scenes.
//
//   pathlab_bench direct   RMSE of 1, 2a, 2b, 2c, 3 against a high-spp reference, at equal
//                          spp and at equal time, and samples per second
//   pathlab_bench pt       the same for the path tracers 4a, 4b, 4c (reference: pt-mis)
//
// RMSE is over all pixels and channels of the linear image, with the reference's own noise
// removed (its mean squared standard error is subtracted from the measured MSE). Timed
// figures are medians over --repeats runs with different seeds, all measured in one process
// so that ratios between estimators are meaningful on a shared machine.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "render/renderer.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab {
namespace {

struct Options {
    int size = 128;
    int ref_spp = 4096;
    int spp = 16;
    double seconds = 1.0;
    int repeats = 3;
    std::string scenes = "0,1,2,3,4,5,6,7";
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Reference {
    Image mean;
    double noise_mse = 0;  // mean squared standard error of the reference
};

double rmse(const Image& img, const Reference& ref) {
    double sum = 0;
    for (size_t i = 0; i < img.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double d = double(img[i][c]) - ref.mean[i][c];
            sum += d * d;
        }
    return std::sqrt(std::max(0.0, sum / double(3 * img.pixel_count()) - ref.noise_mse));
}

RenderResult run(const Scene& scene, const std::string& algorithm, const Options& o, int spp, double seconds,
                 uint64_t seed) {
    const auto estimator = find_estimator(algorithm)->make({});
    RenderSettings rs;
    rs.width = rs.height = o.size;
    rs.spp = spp;
    rs.time_limit = seconds;
    rs.seed = seed;
    return render(scene, *estimator, rs);
}

Reference make_reference(const Scene& scene, const std::string& algorithm, const Options& o) {
    const RenderResult r = run(scene, algorithm, o, o.ref_spp, 0, 987654321);
    Reference ref{r.film.mean(), 0};
    const Image se = r.film.standard_error();
    for (size_t i = 0; i < se.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) ref.noise_mse += double(se[i][c]) * se[i][c];
    ref.noise_mse /= double(3 * se.pixel_count());
    return ref;
}

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

// One table: for each scene, each algorithm's RMSE at equal spp, RMSE at equal time, samples/s.
void efficiency_table(const Options& o, const std::vector<std::string>& algorithms, const std::string& reference_algorithm) {
    fmt::print("resolution {0}x{0}; reference: {1} at {2} spp; equal spp: {3}; equal time: {4} s; medians of {5} runs\n\n",
               o.size, reference_algorithm, o.ref_spp, o.spp, o.seconds, o.repeats);
    fmt::print("| scene | estimator | RMSE @ {} spp | RMSE @ {} s | spp in {} s | Msamples/s | Mrays/s |\n", o.spp, o.seconds,
               o.seconds);
    fmt::print("|---|---|---|---|---|---|---|\n");
    for (int index : parse_scenes(o.scenes)) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const Reference ref = make_reference(*scene, reference_algorithm, o);
        for (const std::string& a : algorithms) {
            const double equal_spp = rmse(run(*scene, a, o, o.spp, 0, 1).film.mean(), ref);
            std::vector<double> err, spp, msps, mrps;
            for (int k = 0; k < o.repeats; ++k) {
                const RenderResult r = run(*scene, a, o, 0, o.seconds, 100 + uint64_t(k));
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

}  // namespace
}  // namespace pathlab

int main(int argc, char** argv) {
    using namespace pathlab;
    CLI::App app{"pathlab benchmarks: estimator efficiency on the course scenes"};
    app.require_subcommand(1);
    Options o;
    for (CLI::App* sub : {app.add_subcommand("direct", "Direct-illumination estimators 1, 2a, 2b, 2c, 3"),
                          app.add_subcommand("pt", "Path tracers 4a, 4b, 4c")}) {
        sub->add_option("--size", o.size, "Image width and height")->capture_default_str();
        sub->add_option("--ref-spp", o.ref_spp, "Samples per pixel of the reference")->capture_default_str();
        sub->add_option("--spp", o.spp, "Samples per pixel for the equal-spp column")->capture_default_str();
        sub->add_option("--seconds", o.seconds, "Time per render for the equal-time column")->capture_default_str();
        sub->add_option("--repeats", o.repeats, "Timed runs per cell (median reported)")->capture_default_str();
        sub->add_option("--scenes", o.scenes, "Comma-separated scene indices")->capture_default_str();
    }
    CLI11_PARSE(app, argc, argv);
    if (app.got_subcommand("direct"))
        efficiency_table(o, {"direct-light", "direct-uniform", "direct-cosine", "direct-brdf", "direct-mis"}, "direct-mis");
    if (app.got_subcommand("pt")) efficiency_table(o, {"pt-naive", "pt-mis3", "pt-mis"}, "pt-mis");
    return 0;
}
