#include "bench_common.hpp"

#include <sys/resource.h>

#include "integrators/integrator.hpp"

namespace pathlab::bench {

RenderResult run(const Scene& scene, const std::string& algorithm, int size, int spp, double seconds, uint64_t seed,
                 std::function<void(const Film&, const RenderStats&)> after_pass, SamplerKind sampler) {
    const auto estimator = find_integrator(algorithm)->make({});
    RenderSettings rs;
    rs.width = rs.height = size;
    rs.spp = spp;
    rs.time_limit = seconds;
    rs.seed = seed;
    rs.after_pass = std::move(after_pass);
    rs.sampler = sampler;
    return render(scene, *estimator, rs);
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
