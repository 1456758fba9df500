// `pathlab_bench ic` (part of `make bench`): ic and pbgi against pt-mis and bdpt at equal time
// (1, 4 and 16 s by default) on the diffuse course scenes against a long pt-mis reference (its
// noise subtracted), in interleaved rounds; ic's records and pbgi's surfels and their build
// times; and their bias, left when the noise is gone: the RMS difference of a long render from
// the reference with both images' noise subtracted. `pathlab_bench pbgi-gather`: pbgi's gather
// against a ray-traced truth, per cutoff and micro-buffer resolution.
#include "irradiance_caching.hpp"

#include <tbb/task_arena.h>

#include <time.h>

#include <cstdio>

#include <fmt/format.h>

#include "bench_common.hpp"
#include <tbb/parallel_for.h>

#include "core/sampling.hpp"
#include "integrators/cache/surfel_tree.hpp"
#include "integrators/photon/photon_grid.hpp"
#include "integrators/common/shading.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::bench {
namespace {

double statistic(const RenderStats& s, const std::string& name) {
    for (const IntegratorStatistic& x : s.integrator)
        if (x.name == name) return x.value;
    return 0;
}

double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

void pbgi_gather_suite(const GatherAccuracyOptions& o) {
    fmt::print("## pbgi's gather against the truth ({} first hits per scene, about {} surfels, one surfel bounce; truth: 4096 "
               "stratified rays whose hits take the nearest surfel's radiance; processor time of one thread)\n\n",
               o.points, o.surfels);
    fmt::print("| scene | buffer | cutoff sr | rel. RMS error | rel. mean error | us per gather | clusters | surfels |\n"
               "|---|---|---|---|---|---|---|---|\n");
    for (const int index : o.scenes) {
        SceneDescription desc = make_builtin_scene(index);
        const auto scene = Scene::build(desc);
        std::vector<Surfel> surfels = make_surfels(*scene, size_t(o.surfels));
        light_surfels(*scene, surfels, 16, 1, SamplerKind::Independent);
        const SurfelTree tree(std::move(surfels));
        const PerspectiveCamera camera(scene->camera(), 64, 64);
        std::vector<std::pair<Vec3f, Vec3f>> points;
        Sampler pick(3, 0, 0);
        while (int(points.size()) < o.points) {
            const Ray ray = camera.generate(64 * pick.next1d(), 64 * pick.next1d());
            Intersection hit;
            if (!scene->intersect(ray, hit)) continue;
            const ShadingPoint sp = make_shading_point(*scene, hit, ray.d);
            if (sp.material->is_black()) continue;
            points.push_back({sp.p, sp.frame.n});
        }
        // The truth the gathers aim at: the irradiance from the surfels' radiance on the real
        // surfaces, by 64 x 64 stratified cosine-distributed rays whose hits take the radiance of
        // the nearest surfel on the same surface (the side facing the ray).
        PhotonKdTree kd;
        kd.build(tree.surfels(), 0.1f);  // their centres
        std::vector<Rgb> reference(points.size());
        tbb::parallel_for(size_t(0), points.size(), [&](size_t i) {
            const Frame frame(points[i].second);
            Vec3d sum(0.0);
            Sampler sampler(9, i, 0);
            constexpr int M = 64;
            for (int a = 0; a < M; ++a)
                for (int b = 0; b < M; ++b) {
                    const Vec2f u = sampler.next2d();
                    const Vec3f d = frame.to_world(square_to_cosine_hemisphere({(float(a) + u.x) / M, (float(b) + u.y) / M}));
                    Intersection hit;
                    if (!scene->intersect(spawn_ray(points[i].first, points[i].second, d), hit)) continue;
                    uint32_t idx[16];
                    float d2[16];
                    const size_t found = kd.nearest(hit.p, 16, idx, d2);
                    for (size_t k = 0; k < found; ++k) {
                        const Surfel& s = tree.surfels()[idx[k]];
                        if (std::abs(dot(s.n, hit.ng)) < 0.9f) continue;
                        sum += Vec3d(s.radiance[dot(d, s.n) < 0 ? 0 : 1]);
                        break;
                    }
                }
            reference[i] = Rgb(sum * (double(kPi) / (M * M)));
        });
        std::vector<float> cutoffs = o.cutoffs;
        cutoffs.insert(cutoffs.begin(), 0.0f);
        for (const int res : o.resolutions)
            for (const float cutoff : cutoffs) {
                const GatherSettings s{cutoff, res};
                GatherCounters counters;
                std::vector<Rgb> E(points.size());
                // Processor time (the machine is shared): this thread's alone.
                const double start = thread_seconds();
                for (size_t i = 0; i < points.size(); ++i) E[i] = tree.gather(points[i].first, points[i].second, s, &counters);
                const double us = (thread_seconds() - start) * 1e6 / double(points.size());
                double se = 0, sr = 0, sd = 0;
                for (size_t i = 0; i < points.size(); ++i)
                    for (int c = 0; c < 3; ++c) {
                        const double d = double(E[i][c]) - reference[i][c];
                        se += d * d, sd += d, sr += double(reference[i][c]) * reference[i][c];
                    }
                double mean_ref = 0;
                for (const Rgb& r : reference) mean_ref += (double(r[0]) + r[1] + r[2]) / 3;
                mean_ref /= double(points.size());
                const double g = double(counters.gathers);
                fmt::print("| {} | {} | {:g} | {:.4f} | {:+.4f} | {:.1f} | {:.0f} | {:.0f} |\n", index, res, cutoff, std::sqrt(se / sr),
                           sd / double(3 * points.size()) / mean_ref, us, double(counters.clusters) / g, double(counters.surfels) / g);
                std::fflush(stdout);
            }
    }
}

void irradiance_caching_suite(const IrradianceCachingOptions& o) {
    const int threads = std::min(2, tbb::this_task_arena::max_concurrency());
    const std::vector<std::string> algorithms{"pt-mis", "bdpt", "ic", "pbgi"};
    fmt::print("## ic and pbgi at equal time, {0}x{0} ({1} threads, medians of {2} rounds; reference: pt-mis at {3} spp, its noise "
               "subtracted)\n\n",
               o.size, threads, o.repeats, o.ref_spp);
    fmt::print("| scene | budget s | pt-mis RMSE | bdpt RMSE | ic RMSE | pbgi RMSE | ic / pt-mis MSE | pbgi / pt-mis MSE | ic records | "
               "ic cache s | pbgi surfels | pbgi cache s |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const int index : o.scenes) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const Reference ref = make_reference(*scene, "pt-mis", o.size, o.ref_spp);
        for (const double budget : o.budgets) {
            std::vector<std::vector<double>> errors(algorithms.size());
            std::vector<double> records, ic_seconds, surfels, pbgi_seconds;
            for (int k = 0; k < o.repeats; ++k)
                for (size_t a = 0; a < algorithms.size(); ++a) {
                    const RenderResult r = run(*scene, algorithms[a], o.size, 0, budget, 500 + uint64_t(k));
                    errors[a].push_back(rmse(r.film.mean(), ref));
                    if (algorithms[a] == "ic") {
                        records.push_back(statistic(r.stats, "records"));
                        ic_seconds.push_back(statistic(r.stats, "cache_seconds"));
                    } else if (algorithms[a] == "pbgi") {
                        surfels.push_back(statistic(r.stats, "surfels"));
                        pbgi_seconds.push_back(statistic(r.stats, "cache_seconds"));
                    }
                }
            const double pt = median(errors[0]), ic = median(errors[2]), pb = median(errors[3]);
            const auto ratio = [pt](double e) { return pt > 0 ? e * e / (pt * pt) : 0.0; };
            fmt::print("| {} | {:g} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {:.2f} | {:.2f} | {:.0f} | {:.2f} | {:.0f} | {:.2f} |\n", index,
                       budget, pt, median(errors[1]), ic, pb, ratio(ic), ratio(pb), median(records), median(ic_seconds), median(surfels),
                       median(pbgi_seconds));
            std::fflush(stdout);
        }
        // The bias left: long ic and pbgi renders (their noise and the reference's subtracted).
        std::string row = fmt::format("| {} | bias at {} spp | | |", index, o.ref_spp / 2);
        for (const std::string& algorithm : {std::string("ic"), std::string("pbgi")}) {
            const RenderResult r = run(*scene, algorithm, o.size, o.ref_spp / 2, 0, 77);
            const Image se = r.film.standard_error();
            double sum = 0;
            for (size_t i = 0; i < se.pixel_count(); ++i)
                for (int c = 0; c < 3; ++c) {
                    const double d = double(r.film.mean()[i][c]) - ref.mean[i][c];
                    sum += d * d - double(se[i][c]) * se[i][c];
                }
            row += fmt::format(" {:.4f} |", std::sqrt(std::max(0.0, sum / double(3 * se.pixel_count()) - ref.noise_mse)));
        }
        fmt::print("{} | | | | | | |\n", row);
        std::fflush(stdout);
    }
}

}  // namespace pathlab::bench
