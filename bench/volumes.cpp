// `pathlab_bench volumes` (part of `make bench`):
//  0. the price of media support: volpath against pt-mis on course scenes without media (the same
//     image, bit for bit), time per sample at a fixed spp, in interleaved pairs; must be near 1;
//  1. throughput: volpath samples per second on the fog scenes and the smoke, next to pt-mis's
//     paths per second on the same files (pt-mis does not see the media), with rays per sample;
//  2. equal time: RMSE of volpath with and without MIS (light sampling and phase/BSDF sampling
//     combined by the balance heuristic, or light sampling alone) against a long volpath
//     reference whose noise is subtracted (bench_common.hpp), in interleaved pairs;
//  3. optical thickness: the fog of fog-box.xml scaled so that sigma_t x the box's width is 0.1,
//     1 and 10 (grey, albedo 0.8): time and rays per sample, and the mean path length.
#include "volumes.hpp"

#include <tbb/task_arena.h>

#include <cstdio>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "integrators/path/volpath.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {
namespace {

SceneDescription scene_file(const std::string& name) { return load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + name); }

struct Timed {
    double rmse = 0, spp = 0, seconds = 0, msamples = 0, rays_per_sample = 0;
};

Timed timed(const Scene& scene, Integrator& integrator, int size, double seconds, uint64_t seed, const Reference* ref) {
    RenderSettings rs;
    rs.width = rs.height = size;
    rs.time_limit = seconds;
    rs.seed = seed;
    const RenderResult r = render(scene, integrator, rs);
    Timed t;
    t.spp = double(r.stats.spp);
    t.seconds = r.stats.seconds;
    t.msamples = double(r.stats.samples) / r.stats.seconds * 1e-6;
    t.rays_per_sample = double(r.stats.rays) / double(r.stats.samples);
    if (ref) t.rmse = rmse(r.film.mean(), *ref);
    return t;
}

}  // namespace

void volumes_suite(const VolumesOptions& o) {
    const int threads = std::min(2, tbb::this_task_arena::max_concurrency());
    IntegratorOptions options;
    const auto volpath = make_volpath(options), volpath_no_mis = make_volpath(options, {false});
    const auto volpath_own_loop = make_volpath(options, {true, false});  // no pt-mis shortcut without media
    const auto pt_mis = find_integrator("pt-mis")->make(options);

    fmt::print("## volpath against pt-mis without media: {0}x{0}, {1} spp per render, {2} threads (median of {3} interleaved "
               "pairs of the time ratio)\n\n",
               o.size, o.fixed_spp, threads, o.repeats);
    fmt::print("| scene | pt-mis s | volpath s | volpath / pt-mis | volpath's own loop / pt-mis |\n|---|---|---|---|---|\n");
    for (const std::string& name : o.plain_scenes) {
        const auto scene = Scene::build(scene_file(name));
        std::vector<double> tp, tv, ratio, own;
        for (int k = 0; k < o.repeats; ++k) {
            RenderSettings rs;
            rs.width = rs.height = o.size;
            rs.spp = uint64_t(o.fixed_spp);
            rs.seed = 500 + uint64_t(k);
            // Alternate which goes first, so a drift of the machine's load favours neither.
            double a = 0, b = 0;
            if (k % 2 == 0) {
                a = render(*scene, *pt_mis, rs).stats.seconds;
                b = render(*scene, *volpath, rs).stats.seconds;
            } else {
                b = render(*scene, *volpath, rs).stats.seconds;
                a = render(*scene, *pt_mis, rs).stats.seconds;
            }
            const double c = render(*scene, *volpath_own_loop, rs).stats.seconds;
            tp.push_back(a), tv.push_back(b), ratio.push_back(b / a), own.push_back(c / a);
        }
        fmt::print("| {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} |\n", name, median(tp), median(tv), median(ratio), median(own));
        std::fflush(stdout);
    }

    fmt::print("\n## volpath at equal time, {0}x{0}, {1} s per render, {2} threads (medians of {3} interleaved rounds; "
               "reference: volpath at {4} spp, its noise subtracted)\n\n",
               o.size, o.seconds, threads, o.repeats, o.ref_spp);
    fmt::print("| scene | volpath Msamples/s | rays/sample | pt-mis Mpaths/s (media ignored) | time/sample volpath / pt-mis | RMSE MIS | "
               "RMSE no MIS | efficiency MIS / no MIS | spp MIS | spp no MIS |\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (const std::string& name : o.scenes) {
        const auto scene = Scene::build(scene_file(name));
        const Reference ref = make_reference(*scene, "volpath", o.size, o.ref_spp);
        std::vector<double> rate, rays, pt_rate, cost, with, without, ratio, spp_with, spp_without;
        for (int k = 0; k < o.repeats; ++k) {
            const Timed a = timed(*scene, *volpath, o.size, o.seconds, 100 + uint64_t(k), &ref);
            const Timed b = timed(*scene, *volpath_no_mis, o.size, o.seconds, 200 + uint64_t(k), &ref);
            const Timed p = timed(*scene, *pt_mis, o.size, o.seconds / 2, 300 + uint64_t(k), nullptr);
            rate.push_back(a.msamples), rays.push_back(a.rays_per_sample), pt_rate.push_back(p.msamples);
            cost.push_back(p.msamples / a.msamples);
            with.push_back(a.rmse), without.push_back(b.rmse), spp_with.push_back(a.spp), spp_without.push_back(b.spp);
            // Efficiency is 1 / (MSE x time): the ratio corrects for renders ending a little apart.
            ratio.push_back((b.rmse * b.rmse * b.seconds) / (a.rmse * a.rmse * a.seconds));
        }
        fmt::print("| {} | {:.3f} | {:.2f} | {:.3f} | {:.2f} | {:.4f} | {:.4f} | {:.2f} | {:.0f} | {:.0f} |\n", name, median(rate),
                   median(rays), median(pt_rate), median(cost), median(with), median(without), median(ratio), median(spp_with),
                   median(spp_without));
        std::fflush(stdout);
    }

    fmt::print("\n## Cost against optical thickness: fog-box.xml with a grey fog (albedo 0.8) of sigma_t x 2.56 (the box's width) "
               "= 0.1, 1, 10; {0}x{0}, {1} s per render (medians of {2})\n\n",
               o.size, o.seconds, o.repeats);
    fmt::print("| sigma_t x size | sigma_t | volpath Msamples/s | us/sample | rays/sample | time / time at 0.1 |\n|---|---|---|---|---|---|\n");
    double base = 0;
    for (const double thickness : {0.1, 1.0, 10.0}) {
        SceneDescription d = scene_file("fog-box.xml");
        const float sigma = float(thickness / 2.56);
        d.media[0] = HomogeneousMedium{Rgb(sigma), Rgb(0.8f * sigma), HgPhase{0.3f}};
        const auto scene = Scene::build(d);
        std::vector<double> rate, rays;
        for (int k = 0; k < o.repeats; ++k) {
            const Timed a = timed(*scene, *volpath, o.size, o.seconds, 400 + uint64_t(k), nullptr);
            rate.push_back(a.msamples), rays.push_back(a.rays_per_sample);
        }
        const double us = 1 / median(rate);
        if (base == 0) base = us;
        fmt::print("| {:g} | {:.4f} | {:.3f} | {:.2f} | {:.2f} | {:.2f} |\n", thickness, sigma, median(rate), us, median(rays), us / base);
        std::fflush(stdout);
    }
}

}  // namespace pathlab::bench
