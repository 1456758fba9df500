#include "bench_common.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "job/render_job.hpp"

namespace pathlab::bench {

RenderResult run(const Scene& scene, const std::string& algorithm, int size, int spp, double seconds, uint64_t seed,
                 std::function<void(const Film&, const RenderStats&)> after_pass, SamplerKind sampler) {
    JobRequest r;
    // "name:key=value:...": radius (the photon methods' first radius), max_depth, rr_depth, ppg's
    // guiding_spp, guiding_rr (1: on), guiding_fraction (a number or learned) and guiding (sd-tree or vmm), and upbp's estimators (joined by '+': estimators=bpt+pb2d).
    r.algorithm = algorithm.substr(0, algorithm.find(':'));
    for (size_t at = algorithm.find(':'); at != std::string::npos;) {
        const size_t next = algorithm.find(':', at + 1);
        const std::string setting = algorithm.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
        const size_t eq = setting.find('=');
        const std::string key = setting.substr(0, eq), value = eq == std::string::npos ? "" : setting.substr(eq + 1);
        if (key == "radius") r.photon_radius = std::stof(value);
        else if (key == "max_depth") r.max_depth = std::stoi(value);
        else if (key == "rr_depth") r.rr_depth = std::stoi(value);
        else if (key == "guiding_spp") r.guiding_spp = std::stoi(value);
        else if (key == "guiding_rr") r.guiding_rr = value != "0";
        else if (key == "guiding_fraction") r.guiding_fraction = value;
        else if (key == "guiding") r.guiding = value;
        else if (key == "beam_radius") r.beam_radius = std::stof(value);
        else if (key == "estimators") {
            std::string list = value;
            std::replace(list.begin(), list.end(), '+', ',');
            r.estimators = list;
        } else
            throw std::runtime_error(
                fmt::format("{}: unknown setting '{}' (radius, max_depth, rr_depth, guiding_spp, guiding_rr, guiding_fraction, guiding, estimators, beam_radius)", algorithm, key));
        at = next;
    }
    r.width = r.height = size;
    if (spp > 0) r.spp = uint64_t(spp);
    r.time_limit = seconds;
    r.seed = seed;
    r.sampler = sampler;
    // The scene's light sampler (the job refuses a shared scene built with another one).
    if (scene.light_sampler().kind() != LightSamplerKind::Power) r.light_sampler = scene.light_sampler().kind();
    if (scene.light_sampler().kind() == LightSamplerKind::Bvh) r.light_split = scene.light_sampler().split();
    // The caller's scene, shared without ownership: its BVH is built once for many runs.
    RenderJob job(scene_choice_of(scene.description()), r, std::shared_ptr<const Scene>(std::shared_ptr<const Scene>(), &scene));
    job.settings.after_pass = std::move(after_pass);
    return job.run();
}

Reference make_reference(const Scene& scene, const std::string& algorithm, int size, int spp) {
    const RenderResult r = run(scene, algorithm, size, spp, 0, 987654321);
    Reference ref{r.film.mean(), 0};
    const Image se = r.film.standard_error();
    for (size_t i = 0; i < se.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) ref.noise_mse += double(se[i][c]) * se[i][c];
    ref.noise_mse /= double(3 * se.pixel_count());
    return ref;
}

double peak_rss_mib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;  // Linux reports KiB
}

}  // namespace pathlab::bench
