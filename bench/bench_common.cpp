#include "bench_common.hpp"

#include <sys/resource.h>

#include "job/render_job.hpp"

namespace pathlab::bench {

RenderResult run(const Scene& scene, const std::string& algorithm, int size, int spp, double seconds, uint64_t seed,
                 std::function<void(const Film&, const RenderStats&)> after_pass, SamplerKind sampler) {
    JobRequest r;
    r.algorithm = algorithm;
    if (const size_t colon = algorithm.find(":radius="); colon != std::string::npos) {
        r.algorithm = algorithm.substr(0, colon);
        r.photon_radius = std::stof(algorithm.substr(colon + 8));
    }
    r.width = r.height = size;
    if (spp > 0) r.spp = uint64_t(spp);
    r.time_limit = seconds;
    r.seed = seed;
    r.sampler = sampler;
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
