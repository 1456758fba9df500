// `pathlab_bench pm` (part of `make bench`): the photons of a few scenes (bdpt's light subpaths
// at their non-Dirac vertices after one bounce, as sppm stores them), traced per second; then
// the hashed grid against nanoflann's k-d tree: build time, the time of one radius query per
// pixel's visible point (the first non-Dirac camera hit), and memory. Medians of repeats. Then
// vcm's iterations: light vertices and photons stored, bytes per photon, time per iteration.
// Then the equal-time RMSE of pt-mis, bdpt, pm, ppm, sppm, bpm and vcm against a long bdpt
// reference (vcm's on the specular-diffuse-specular scene, where bdpt misses light), its noise
// subtracted, in interleaved rounds.
#include "photon_mapping.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdio>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "integrators/bidir/bdpt.hpp"
#include "integrators/photon/photon_grid.hpp"
#include "integrators/photon/vcm.hpp"
#include "job/scene_choice.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

SceneDescription scene_of(const std::string& key) {
    if (looks_like_scene_file(key)) return load_scene_file(std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + key);
    return make_builtin_scene(std::stoi(key));
}

using RgbPhoton = Photon<RgbTransport>;

std::vector<RgbPhoton> trace(const RenderContext& ctx, int paths, double& seconds) {
    const Bdpt<RgbTransport> walker({});
    const auto t0 = Clock::now();
    const int chunks = 256, per = (paths + chunks - 1) / chunks;
    std::vector<std::vector<RgbPhoton>> out(static_cast<size_t>(chunks));
    tbb::parallel_for(0, chunks, [&](int c) {
        std::vector<PathVertex<RgbTransport>> path;
        for (int j = c * per; j < std::min(paths, (c + 1) * per); ++j) {
            Sampler sampler(ctx.seed, uint64_t(j), 0);
            walker.light_subpath(ctx, sampler, RgbWavelengths{}, path);
            for (size_t v = 2; v < path.size(); ++v)
                if (path[v].kind == VertexKind::Surface && path[v].connectible())
                    out[size_t(c)].push_back({path[v].p, path[v].sp.frame.to_world(path[v].sp.wi), path[v].beta, uint16_t(v), 0});
        }
    });
    std::vector<RgbPhoton> photons;
    for (const auto& c : out) photons.insert(photons.end(), c.begin(), c.end());
    seconds = ms_since(t0) * 1e-3;
    return photons;
}

// Each pixel's first non-Dirac camera hit (pixels that see nothing are left out).
std::vector<Vec3f> visible_points(const RenderContext& ctx) {
    std::vector<Vec3f> points;
    for (size_t p = 0; p < ctx.pixel_count(); ++p) {
        Ray ray = ctx.camera.generate(float(p % size_t(ctx.width)) + 0.5f, float(p / size_t(ctx.width)) + 0.5f);
        Sampler sampler(1, p, 0);
        for (int k = 0; k < 8; ++k) {
            Intersection hit;
            if (!ctx.scene.intersect(ray, hit)) break;
            const ShadingPoint sp = make_shading_point(ctx.scene, hit, normalize(ray.d));
            if (!sp.material->is_delta()) {
                points.push_back(hit.p);
                break;
            }
            const auto s = sp.material->sample(sp, sp.wi, sampler.next2d());
            if (!s) break;
            ray = sp.spawn(s->wo);
        }
    }
    return points;
}

template <typename Search>
void time_search(const std::vector<RgbPhoton>& photons, const std::vector<Vec3f>& queries, float r, int repeats, double& build_ms,
                 double& query_ms, double& found) {
    std::vector<double> builds, queries_ms;
    for (int k = 0; k < repeats; ++k) {
        Search s;
        auto t0 = Clock::now();
        s.build(photons, r);
        builds.push_back(ms_since(t0));
        std::vector<double> sums(queries.size());
        t0 = Clock::now();
        tbb::parallel_for(size_t(0), queries.size(), [&](size_t i) {
            double n = 0;
            s.for_each_within(queries[i], r, [&](uint32_t k) { n += double(photons[k].power.x > -1); });
            sums[i] = n;
        });
        queries_ms.push_back(ms_since(t0));
        found = 0;
        for (const double n : sums) found += n;
        found /= double(std::max<size_t>(1, queries.size()));
    }
    build_ms = median(builds), query_ms = median(queries_ms);
}

}  // namespace

void photon_mapping_suite(const PhotonMappingOptions& o) {
    const int threads = std::min(2, tbb::this_task_arena::max_concurrency());
    fmt::print("## Photons: {} light paths per scene; range search at {}x{} visible points, r = {} x the scene's radius "
               "({} threads, medians of {})\n\n",
               o.light_paths, o.size, o.size, o.radius_factor, threads, o.repeats);
    fmt::print("| scene | photons | Mphotons/s | grid build ms | k-d tree build ms | grid query ms | k-d tree query ms | photons per query "
               "| grid / k-d tree (build + query) |\n|---|---|---|---|---|---|---|---|---|\n");
    for (const std::string& key : o.scenes) {
        const auto scene = Scene::build(scene_of(key));
        const PerspectiveCamera camera(scene->camera(), o.size, o.size);
        const RenderContext ctx{*scene, camera, o.size, o.size, 5, SamplerKind::Independent, 32};
        double seconds = 0;
        const std::vector<RgbPhoton> photons = trace(ctx, o.light_paths, seconds);
        const std::vector<Vec3f> queries = visible_points(ctx);
        const float r = o.radius_factor * scene->scene_sphere().radius;
        double gb = 0, gq = 0, gf = 0, kb = 0, kq = 0, kf = 0;
        time_search<PhotonGrid>(photons, queries, r, o.repeats, gb, gq, gf);
        time_search<PhotonKdTree>(photons, queries, r, o.repeats, kb, kq, kf);
        if (gf != kf) fmt::print("(the two searches found different photons: {} against {})\n", gf, kf);
        fmt::print("| {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} |\n", key, photons.size(),
                   double(photons.size()) / seconds * 1e-6, gb, kb, gq, kq, gf, (gb + gq) / (kb + kq));
        std::fflush(stdout);
    }
    fmt::print("\n## vcm's iterations at {0}x{0} ({0}^2 light paths each; {1} threads, medians of {2})\n\n", o.equal_time_size, threads, o.repeats);
    fmt::print("| scene | light vertices | photons | MB held | bytes per photon | ms per iteration | Mphotons/s |\n|---|---|---|---|---|---|---|\n");
    for (const std::string& key : o.scenes) {
        const auto scene = Scene::build(scene_of(key));
        const PerspectiveCamera camera(scene->camera(), o.equal_time_size, o.equal_time_size);
        const RenderContext ctx{*scene, camera, o.equal_time_size, o.equal_time_size, 5, SamplerKind::Independent, 32};
        Vcm<RgbTransport> vcm({});
        Film film(o.equal_time_size, o.equal_time_size);
        std::vector<double> ms;
        for (int k = 0; k < o.repeats; ++k) {
            const auto t0 = Clock::now();
            vcm.render_passes(ctx, film, uint64_t(k), 1, {});
            ms.push_back(ms_since(t0));
        }
        const double photons = double(vcm.photon_count());
        fmt::print("| {} | {} | {} | {:.2f} | {:.0f} | {:.1f} | {:.2f} |\n", key, vcm.light_vertex_count(), vcm.photon_count(),
                   double(vcm.memory_bytes()) / (1 << 20), double(vcm.memory_bytes()) / std::max(1.0, photons), median(ms),
                   photons / median(ms) * 1e-3);
        std::fflush(stdout);
    }
    fmt::print("\n(A light vertex is {} bytes: vcm keeps whole subpaths for its connections; sppm keeps only the photons.)\n",
               sizeof(PathVertex<RgbTransport>));

    fmt::print("\n## Equal time at {0}x{0}, {1} s per render ({2} threads, medians of {3} rounds; reference: bdpt at {4} spp, "
               "vcm on sds-caustic.xml, its noise subtracted)\n\n",
               o.equal_time_size, o.equal_time_seconds, threads, o.equal_time_repeats, o.ref_spp);
    const std::vector<std::string> algorithms{"pt-mis", "bdpt", "pm", "ppm", "sppm", "bpm", "vcm"};
    fmt::print("| scene |");
    for (const auto& a : algorithms) fmt::print(" {} RMSE |", a);
    fmt::print(" lowest |\n|---|");
    for (size_t k = 0; k <= algorithms.size(); ++k) fmt::print("---|");
    fmt::print("\n");
    for (const std::string& key : o.scenes) {
        const auto scene = Scene::build(scene_of(key));
        const Reference ref = make_reference(*scene, key == "sds-caustic.xml" ? "vcm" : "bdpt", o.equal_time_size, o.ref_spp);
        std::vector<std::vector<double>> errors(algorithms.size());
        for (int k = 0; k < o.equal_time_repeats; ++k)
            for (size_t a = 0; a < algorithms.size(); ++a) {
                const RenderResult r = run(*scene, algorithms[a], o.equal_time_size, 0, o.equal_time_seconds, 300 + uint64_t(k));
                errors[a].push_back(rmse(r.film.mean(), ref));
            }
        std::string row = "| " + key;
        size_t best = 0;
        for (size_t a = 0; a < algorithms.size(); ++a) {
            // 0: below what the reference's own noise lets the measure see
            row += median(errors[a]) > 0 ? fmt::format(" | {:.4f}", median(errors[a])) : " | < reference noise";
            if (median(errors[a]) < median(errors[best])) best = a;
        }
        const double bdpt = median(errors[1]), vcm = median(errors[6]);
        fmt::print("{} | {} |{}\n", row, algorithms[best],
                   vcm > 0 ? fmt::format(" (bdpt / vcm MSE {:.2f})", bdpt * bdpt / (vcm * vcm)) : "");
        std::fflush(stdout);
    }

    fmt::print("\nMemory: a photon is {} bytes; the grid adds 8 bytes per photon (cell ends and the sorted order), the k-d tree\n"
               "its nodes and index (nanoflann: leaves of up to 10 points).\n",
               sizeof(RgbPhoton));
}

}  // namespace pathlab::bench
