// The performance suite (`pathlab_bench perf`, run by `make bench`):
//   1. samples/s and rays/s of every estimator on the chosen scenes, with 1 and 2 threads;
//   2. Embree's raw closest-hit throughput for incoherent rays in the same scenes (random
//      origins inside the scene's bounding box, uniformly random directions), the upper bound
//      for pathlab's rays/s, and pathlab's own intersect() on the same rays;
//   3. BVH build time and per-sample cost as a tessellated sphere of 1k..1M triangles is added
//      to the box;
//   4. efficiency of pt-mis with the independent and the Sobol sampler: RMSE against a
//      high-spp reference after 5, 10 and 20 seconds, and 1/(MSE x seconds);
// plus peak resident memory. Every figure is a median over repeats measured in this one
// process, so ratios are meaningful on a shared machine. Markdown tables go to stdout, all
// figures to a JSON file (rewritten after each section, so an interrupted run keeps them).
#include "performance.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "samplers/sampler.hpp"
#include "core/sampling.hpp"
#include "instrument/allocation_counter.hpp"
#include "integrators/integrator.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::bench {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void save(const nlohmann::json& j, const std::string& path) {
    if (path.empty()) return;
    const std::filesystem::path p(path);
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
    std::ofstream(path) << j.dump(2) << "\n";
}

// Runs f inside an arena of `threads` worker threads (TBB parallelism is limited to it).
template <class F>
auto with_threads(int threads, F&& f) {
    tbb::task_arena arena(threads);
    return arena.execute(std::forward<F>(f));
}

// ---- 1. estimator throughput ------------------------------------------------------------

struct Throughput {
    double msamples = 0, mrays = 0;
};

Throughput timed_render(const Scene& scene, const std::string& algorithm, int size, double seconds, int threads,
                        uint64_t seed) {
    const RenderResult r = with_threads(threads, [&] { return run(scene, algorithm, size, 0, seconds, seed); });
    return {double(r.stats.samples) / r.stats.seconds * 1e-6, double(r.stats.rays) / r.stats.seconds * 1e-6};
}

// One-thread and N-thread throughput measured back to back, `repeats` times: medians of each,
// and the median of the per-pair ratios (robust to load that comes and goes between pairs).
struct Scaling {
    Throughput one, many;
    double ratio = 0;
};

Scaling measure_scaling(const Scene& scene, const std::string& algorithm, const PerfOptions& o, int threads) {
    std::vector<double> s1, r1, sn, rn, ratio;
    for (int k = 0; k < o.repeats; ++k) {
        const Throughput a = timed_render(scene, algorithm, o.size, o.seconds, 1, 10 + uint64_t(k));
        const Throughput b = timed_render(scene, algorithm, o.size, o.seconds, threads, 10 + uint64_t(k));
        s1.push_back(a.msamples), r1.push_back(a.mrays), sn.push_back(b.msamples), rn.push_back(b.mrays);
        ratio.push_back(b.msamples / a.msamples);
    }
    return {{median(s1), median(r1)}, {median(sn), median(rn)}, median(ratio)};
}

// ---- 2. raw Embree throughput -----------------------------------------------------------

std::vector<Ray> incoherent_rays(const Scene& scene, size_t count) {
    Vec3f lo(kInf), hi(-kInf);
    for (const MeshDesc& m : scene.description().meshes)
        for (const Vec3f& p : m.positions) lo = min(lo, p), hi = max(hi, p);
    const Vec3f c = (lo + hi) * 0.5f, half = (hi - lo) * 0.49f;  // just inside the walls
    std::vector<Ray> rays(count);
    Pcg32 rng(42, 7);
    for (Ray& r : rays) {
        const Vec3f u(rng.next_float(), rng.next_float(), rng.next_float());
        r.o = c + half * (u * 2.0f - Vec3f(1.0f));
        r.d = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
        r.tmax = kInf;
    }
    return rays;
}

// Closest-hit rays per second (millions) through rtcIntersect1 directly, or through pathlab's
// Scene::intersect (which adds the hit point, normals and material lookup).
double raw_mrays(const Scene& scene, const std::vector<Ray>& rays, int threads, bool through_pathlab) {
    RTCScene es = scene.accel().embree_scene();
    const auto trace = [&] {
        return tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, rays.size(), 4096), size_t(0),
            [&](const tbb::blocked_range<size_t>& range, size_t hits) {
                RTCIntersectContext context;
                rtcInitIntersectContext(&context);
                for (size_t i = range.begin(); i != range.end(); ++i) {
                    const Ray& r = rays[i];
                    if (through_pathlab) {
                        Intersection isect;
                        hits += scene.intersect(r, isect);
                        continue;
                    }
                    RTCRayHit rh;
                    rh.ray.org_x = r.o.x, rh.ray.org_y = r.o.y, rh.ray.org_z = r.o.z;
                    rh.ray.dir_x = r.d.x, rh.ray.dir_y = r.d.y, rh.ray.dir_z = r.d.z;
                    rh.ray.tnear = 0, rh.ray.tfar = r.tmax, rh.ray.mask = ~0u, rh.ray.flags = 0, rh.ray.time = 0;
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(es, &context, &rh);
                    hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                }
                return hits;
            },
            std::plus<size_t>());
    };
    const auto t0 = Clock::now();
    const size_t hits = with_threads(threads, trace);
    const double s = seconds_since(t0);
    if (hits == 0) throw std::runtime_error("no ray hit the scene: the raw benchmark is broken");
    return double(rays.size()) / s * 1e-6;
}

// ---- 3. scene growth ---------------------------------------------------------------------

// A UV sphere with about `triangles` triangles (rings x 2 rings segments, two triangles per
// quad), placed between and above the two course spheres.
MeshDesc tessellated_sphere(size_t triangles, uint32_t material) {
    const int rings = std::max(2, int(std::lround(std::sqrt(double(triangles) / 4.0))));
    const int segments = 2 * rings;
    const Vec3f center(0.0f, 0.35f, 0.25f);
    const float radius = 0.3f;
    MeshDesc m;
    m.name = fmt::format("tessellated sphere ({} triangles)", triangles);
    m.material = material;
    for (int i = 0; i <= rings; ++i) {
        const float theta = kPi * float(i) / float(rings);
        for (int j = 0; j < segments; ++j) {
            const float phi = 2 * kPi * float(j) / float(segments);
            const Vec3f n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
            m.positions.push_back(center + n * radius);
        }
    }
    const auto v = [&](int i, int j) { return uint32_t(i * segments + (j % segments)); };
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            if (i > 0) m.triangles.push_back({v(i, j), v(i + 1, j), v(i, j + 1)});
            if (i + 1 < rings) m.triangles.push_back({v(i, j + 1), v(i + 1, j), v(i + 1, j + 1)});
        }
    return m;
}

}  // namespace

bool PerfOptions::has(const std::string& section) const {
    return std::find(sections.begin(), sections.end(), section) != sections.end();
}

void performance_suite(const PerfOptions& o) {
    nlohmann::json report = {{"options",
                              {{"size", o.size},
                               {"seconds_per_run", o.seconds},
                               {"repeats", o.repeats},
                               {"scenes", o.scenes},
                               {"hardware_threads", tbb::this_task_arena::max_concurrency()}}}};
    const int max_threads = std::min(2, tbb::this_task_arena::max_concurrency());

    // 1 + 2: throughput, scaling and the Embree bound, per scene.
    if (o.has("throughput")) {
        fmt::print("## Throughput at {0}x{0} (medians of {1} runs of {2} s)\n\n", o.size, o.repeats, o.seconds);
        fmt::print("| scene | estimator | Msamples/s 1 thr | Msamples/s {0} thr | scaling | Mrays/s {0} thr | rays/sample |\n",
                   max_threads);
        fmt::print("|---|---|---|---|---|---|---|\n");
    }
    std::vector<std::pair<int, nlohmann::json>> bounds;
    const std::vector<IntegratorInfo> none;  // the estimators measured when throughput is not asked for
    for (int index : o.scenes) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const std::string name = fmt::format("{} {}", index, builtin_scenes()[size_t(index)].name);
        for (const IntegratorInfo& e : o.has("throughput") ? integrators() : none) {
            const Scaling sc = measure_scaling(*scene, e.name, o, max_threads);
            const Throughput &one = sc.one, &many = sc.many;
            const double scaling = sc.ratio;
            fmt::print("| {} | {} | {:.3f} | {:.3f} | {:.2f}x | {:.2f} | {:.2f} |\n", name, e.name, one.msamples,
                       many.msamples, scaling, many.mrays, many.mrays / many.msamples);
            std::fflush(stdout);
            report["throughput"].push_back({{"scene", name},
                                            {"estimator", e.name},
                                            {"msamples_per_s_1_thread", one.msamples},
                                            {"msamples_per_s", many.msamples},
                                            {"threads", max_threads},
                                            {"scaling", scaling},
                                            {"mrays_per_s_1_thread", one.mrays},
                                            {"mrays_per_s", many.mrays}});
        }
        // Embree alone, pathlab's intersect() and a pt-mis render, back to back, 5 times; the
        // fraction is the median of the per-round ratios pt-mis / Embree.
        if (!o.has("bound")) continue;
        const std::vector<Ray> rays = incoherent_rays(*scene, o.raw_rays);
        nlohmann::json b = {{"scene", name}, {"rays", o.raw_rays}, {"threads", max_threads}};
        std::vector<double> e1, en, pn, pt, fraction;
        for (int k = 0; k < 5; ++k) {
            e1.push_back(raw_mrays(*scene, rays, 1, false));
            en.push_back(raw_mrays(*scene, rays, max_threads, false));
            pn.push_back(raw_mrays(*scene, rays, max_threads, true));
            pt.push_back(timed_render(*scene, "pt-mis", o.size, o.seconds, max_threads, 30 + uint64_t(k)).mrays);
            fraction.push_back(pt.back() / en.back());
        }
        b["embree_mrays_1_thread"] = median(e1);
        b["embree_mrays"] = median(en);
        b["pathlab_intersect_mrays"] = median(pn);
        b["pt_mis_mrays"] = median(pt);
        b["pt_mis_fraction_of_embree"] = median(fraction);
        bounds.emplace_back(index, b);
        report["embree_bound"].push_back(b);
        save(report, o.json);
    }
    if (o.has("bound")) {
        fmt::print("\n## Embree's raw throughput: incoherent closest-hit rays ({} rays), against pathlab (medians of 5 rounds)\n\n",
                   o.raw_rays);
        fmt::print("| scene | Embree Mrays/s 1 thr | Embree Mrays/s {0} thr | pathlab intersect() Mrays/s {0} thr | pt-mis Mrays/s {0} thr | pt-mis / Embree |\n",
                   max_threads);
        fmt::print("|---|---|---|---|---|---|\n");
    }
    for (const auto& [index, b] : bounds)
        fmt::print("| {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.0f}% |\n", b["scene"].get<std::string>(),
                   b["embree_mrays_1_thread"].get<double>(), b["embree_mrays"].get<double>(),
                   b["pathlab_intersect_mrays"].get<double>(),
                   b["pt_mis_mrays"].get<double>(), 100 * b["pt_mis_fraction_of_embree"].get<double>());

    // 3: scene growth.
    if (o.has("growth")) {
        fmt::print("\n## Scene growth: scene 3 plus a tessellated sphere, pt-mis at {0}x{0}, {1} threads\n\n", o.growth_size,
                   max_threads);
        fmt::print("| triangles added | BVH build (ms) | us per sample | relative to plain box | rays/sample | peak RSS (MiB) |\n");
        fmt::print("|---|---|---|---|---|---|\n");
        // Each size is timed in rounds against the plain box (back to back); the relative cost is
        // the median of the per-round ratios.
        const auto plain_box = Scene::build(make_builtin_scene(3));
        const auto us_per_sample = [&](const Scene& scene, uint64_t seed, double* rays_per_sample) {
            const RenderResult r =
                with_threads(max_threads, [&] { return run(scene, "pt-mis", o.growth_size, 0, o.seconds, seed); });
            if (rays_per_sample) *rays_per_sample = double(r.stats.rays) / double(r.stats.samples);
            return r.stats.seconds / double(r.stats.samples) * 1e6;
        };
        for (size_t n : o.mesh_sizes) {
            SceneDescription d = make_builtin_scene(3);
            if (n > 0) {
                d.materials.push_back(make_phong(Rgb(0.6f)));
                d.meshes.push_back(tessellated_sphere(n, uint32_t(d.materials.size() - 1)));
            }
            const size_t triangles = n > 0 ? d.meshes.back().triangles.size() : 0;
            std::vector<double> builds;
            std::unique_ptr<Scene> scene;
            for (int k = 0; k < 3; ++k) {
                scene.reset();
                const auto t0 = Clock::now();
                scene = with_threads(max_threads, [&] { return Scene::build(d); });
                builds.push_back(seconds_since(t0) * 1e3);
            }
            std::vector<double> cost, relative, rps;
            for (int k = 0; k < o.repeats; ++k) {
                double r = 0;
                const double base = us_per_sample(*plain_box, 20 + uint64_t(k), nullptr);
                cost.push_back(us_per_sample(*scene, 20 + uint64_t(k), &r));
                relative.push_back(cost.back() / base);
                rps.push_back(r);
            }
            const double us = median(cost);
            fmt::print("| {} | {:.1f} | {:.3f} | {:.2f}x | {:.2f} | {:.0f} |\n", triangles, median(builds), us,
                       median(relative), median(rps), peak_rss_mib());
            std::fflush(stdout);
            report["growth"].push_back({{"triangles_added", triangles},
                                        {"bvh_build_ms", median(builds)},
                                        {"us_per_sample", us},
                                        {"relative_cost", median(relative)},
                                        {"rays_per_sample", median(rps)},
                                        {"peak_rss_mib", peak_rss_mib()}});
            save(report, o.json);
        }
    }

    // 4: efficiency of pt-mis over time.
    if (!o.has("efficiency")) return;
    fmt::print("\n## pt-mis efficiency at {0}x{0}: reference {1} spp; checkpoints of one progressive render\n\n",
               o.efficiency_size, o.efficiency_ref_spp);
    fmt::print("| scene | sampler | seconds | spp | RMSE | 1/(MSE x s) |\n|---|---|---|---|---|---|\n");
    for (int index : o.scenes) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const std::string name = fmt::format("{} {}", index, builtin_scenes()[size_t(index)].name);
        const Reference ref = with_threads(max_threads, [&] {
            return make_reference(*scene, "pt-mis", o.efficiency_size, o.efficiency_ref_spp);
        });
        for (const SamplerKind kind : {SamplerKind::Independent, SamplerKind::Sobol}) {
            const char* sampler = kind == SamplerKind::Sobol ? "sobol" : "independent";
            // Checkpoints during one progressive render; the last is the render's end.
            const auto record = [&](const Film& film, const RenderStats& st) {
                const double e = rmse(film.mean(), ref);
                const double efficiency = 1.0 / (e * e * st.seconds);
                fmt::print("| {} | {} | {:.2f} | {} | {:.5f} | {:.4g} |\n", name, sampler, st.seconds, st.spp, e, efficiency);
                std::fflush(stdout);
                report["efficiency"].push_back({{"scene", name},
                                                {"sampler", sampler},
                                                {"seconds", st.seconds},
                                                {"spp", st.spp},
                                                {"rmse", e},
                                                {"inverse_mse_seconds", efficiency}});
            };
            size_t next = 0;
            const auto checkpoint = [&](const Film& film, const RenderStats& st) {
                if (next + 1 >= o.checkpoints.size() || st.seconds < o.checkpoints[next]) return;
                record(film, st);
                while (next + 1 < o.checkpoints.size() && st.seconds >= o.checkpoints[next]) ++next;
            };
            const RenderResult r = with_threads(max_threads, [&] {
                return run(*scene, "pt-mis", o.efficiency_size, 0, o.checkpoints.back(), 77, checkpoint, kind);
            });
            record(r.film, r.stats);
        }
        save(report, o.json);
    }

    // Heap allocations per sample of a whole render (driver included), all threads.
    {
        const auto scene = Scene::build(make_builtin_scene(o.scenes.front()));
        const uint64_t before = allocations_by_all_threads();
        const RenderResult r = with_threads(max_threads, [&] { return run(*scene, "pt-mis", 128, 64, 0, 5); });
        const uint64_t allocations = allocations_by_all_threads() - before;
        report["allocations"] = {{"render", "pt-mis 128x128 64 spp"},
                                 {"allocations", allocations},
                                 {"samples", r.stats.samples},
                                 {"per_sample", double(allocations) / double(r.stats.samples)}};
        fmt::print("\nheap allocations in a pt-mis render of 128x128 at 64 spp (film and driver included): {} "
                   "for {} samples ({:.2g} per sample)\n",
                   allocations, r.stats.samples, double(allocations) / double(r.stats.samples));
    }
    report["peak_rss_mib"] = peak_rss_mib();
    save(report, o.json);
    fmt::print("\npeak resident memory: {:.0f} MiB\n", peak_rss_mib());
    if (!o.json.empty()) fmt::print("figures written to {}\n", o.json);
}

}  // namespace pathlab::bench
