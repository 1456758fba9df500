// `pathlab_bench lights` (part of `make bench`):
//  1. the course's sky scenes (6, 7) with their constant environment, with an envmap of the
//     same constant radiance (map_width x map_width/2 texels), and with the procedural sky of
//     scenes/envmaps/sky.exr (scaled to the same mean radiance): CPU microseconds per sample of
//     pt-mis and bdpt, measured in interleaved rounds (medians), and the ratio to the constant;
//  2. one thread's CPU nanoseconds per call of the environment's light sample, pdf and lookup;
//  3. scene 0 with its point light, a spot and an IES light of the same position: pt-mis's
//     CPU microseconds per sample.
// CPU time rather than wall time: on a shared machine it counts the work done, not the waits.
#include "lights.hpp"

#include <sys/resource.h>
#include <time.h>

#include <map>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "image/image_io.hpp"
#include "samplers/sampler.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::bench {
namespace {

// CPU seconds of the whole process (all threads) and of the calling thread: on a shared
// machine they count the work, not the time spent waiting for a core.
double process_cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
double thread_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::shared_ptr<const EnvMap> constant_map(const Rgb& radiance, int width) {
    return std::make_shared<const EnvMap>(width, width / 2, std::vector<Rgb>(size_t(width) * size_t(width / 2), radiance));
}

// The procedural sky, scaled to the mean radiance of `like` and turned so that its up is +z.
std::shared_ptr<const EnvMap> sky_map(const Rgb& like) {
    const Image img = read_image(std::string(PATHLAB_SOURCE_DIR) + "/scenes/envmaps/sky.exr");
    std::vector<Rgb> texels(img.pixel_count());
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = img[i];
    Frame up_is_z;
    up_is_z.s = {1, 0, 0}, up_is_z.t = {0, 0, 1}, up_is_z.n = {0, -1, 0};
    const EnvMap unscaled(img.width(), img.height(), texels, up_is_z);
    const float k = mean(like) / unscaled.mean_radiance();
    for (Rgb& t : texels) t *= k;
    return std::make_shared<const EnvMap>(img.width(), img.height(), std::move(texels), up_is_z);
}

// CPU microseconds per sample (all threads' CPU time over the samples rendered).
double us_per_sample(const Scene& scene, const std::string& algorithm, const LightsOptions& o, uint64_t seed) {
    const double t0 = process_cpu_seconds();
    const RenderResult r = run(scene, algorithm, o.size, 0, o.seconds, seed);
    return (process_cpu_seconds() - t0) / double(r.stats.samples) * 1e6;
}

// Nanoseconds per call of f(i), one thread, over n calls.
template <typename F>
double ns_per_call(int n, F&& f) {
    float sink = 0;
    const double t0 = thread_cpu_seconds();
    for (int i = 0; i < n; ++i) sink += f(i);
    const double s = thread_cpu_seconds() - t0;
    if (sink == 1234.5f) fmt::print(" ");  // keep the calls
    return s / n * 1e9;
}

}  // namespace

void lights_suite(const LightsOptions& o) {
    fmt::print("## Environment map against the constant environment\n\n");
    fmt::print("{}x{} pixels, {} s per render, {} interleaved rounds (medians); CPU microseconds per sample (all threads' CPU "
               "time over the samples: one sample is a camera path, and for bdpt its light path and connections too); the ratio to the "
               "constant environment.\n\n",
               o.size, o.size, o.seconds, o.repeats);
    fmt::print("| scene | environment | pt-mis us/sample | ratio | bdpt us/sample | ratio |\n|---|---|---|---|---|---|\n");
    for (const int index : o.scenes) {
        const SceneDescription base = make_builtin_scene(index);
        int env = -1;
        for (size_t i = 0; i < base.lights.size(); ++i)
            if (std::holds_alternative<EnvironmentLight>(base.lights[i])) env = int(i);
        if (env < 0) continue;
        const Rgb sky = std::get<EnvironmentLight>(base.lights[size_t(env)]).radiance;
        const std::pair<std::string, FreeLight> variants[] = {
            {"constant", base.lights[size_t(env)]},
            {fmt::format("envmap, constant {}x{}", o.map_width, o.map_width / 2), EnvMapLight{constant_map(sky, o.map_width)}},
            {"envmap, sky.exr 256x128", EnvMapLight{sky_map(sky)}}};
        std::vector<std::unique_ptr<Scene>> scenes;
        for (const auto& [name, light] : variants) {
            SceneDescription d = base;
            d.lights[size_t(env)] = light;
            scenes.push_back(Scene::build(d));
        }
        std::map<std::string, std::vector<double>> t;  // algorithm/variant -> times
        for (int r = 0; r < o.repeats; ++r)
            for (const char* algorithm : {"pt-mis", "bdpt"})
                for (size_t v = 0; v < scenes.size(); ++v)
                    t[fmt::format("{}/{}", algorithm, v)].push_back(us_per_sample(*scenes[v], algorithm, o, uint64_t(r + 1)));
        for (size_t v = 0; v < scenes.size(); ++v) {
            const double pt = median(t[fmt::format("pt-mis/{}", v)]), bd = median(t[fmt::format("bdpt/{}", v)]);
            fmt::print("| {} {} | {} | {:.3f} | {:.2f} | {:.3f} | {:.2f} |\n", index, base.name, variants[v].first, pt,
                       pt / median(t["pt-mis/0"]), bd, bd / median(t["bdpt/0"]));
        }
    }

    fmt::print("\n## One environment call, one thread (CPU nanoseconds; 2 million calls, directions spread over the sphere)\n\n| environment | sample_li | pdf_li | Le (lookup) |\n|---|---|---|---|\n");
    {
        constexpr int kCalls = 2'000'000;
        const Rgb sky(0.5f, 0.8f, 1.0f);
        const std::pair<std::string, Light> envs[] = {{"constant", EnvironmentLight{sky}},
                                                      {fmt::format("envmap {}x{}", o.map_width, o.map_width / 2), EnvMapLight{constant_map(sky, o.map_width)}},
                                                      {"envmap sky.exr", EnvMapLight{sky_map(sky)}}};
        std::vector<Vec3f> dirs(4096);
        Sampler rng(7, 0, 0);
        for (Vec3f& d : dirs) d = square_to_uniform_sphere(rng.next2d());
        for (const auto& [name, light] : envs) {
            const double s = ns_per_call(kCalls, [&](int i) {
                const float a = (float(i % 1021) + 0.5f) / 1021, b = (float(i % 977) + 0.5f) / 977;
                const auto ls = sample_light(light, Vec3f(0.0f), {a, b});
                return ls ? ls->pdfW : 0.0f;
            });
            const double p = ns_per_call(kCalls, [&](int i) { return environment_pdf_li(light, dirs[size_t(i) & 4095]); });
            const double l = ns_per_call(kCalls, [&](int i) { return environment_radiance(light, dirs[size_t(i) & 4095]).x; });
            fmt::print("| {} | {:.1f} | {:.1f} | {:.1f} |\n", name, s, p, l);
        }
    }

    fmt::print("\n## Spot and IES lights against the point light (scene 0, pt-mis, CPU microseconds per sample)\n\n| light | us/sample | ratio |\n|---|---|---|\n");
    {
        const SceneDescription base = make_builtin_scene(0);
        const PointLight point = std::get<PointLight>(base.lights[0]);
        Frame down;
        down.s = {1, 0, 0}, down.t = {0, -1, 0}, down.n = {0, 0, -1};
        const std::pair<std::string, FreeLight> lights[] = {
            {"point", point},
            {"spot (cutoff 60, beam 40)", SpotLight(point.position, {0, 0, -1}, point.intensity, 60, 40)},
            {"ies (asymmetric-full.ies)",
             IesLight{point.position, down, point.intensity / 200.0f,
                      std::make_shared<const IesDistribution>(read_ies_file(std::string(PATHLAB_SOURCE_DIR) + "/tests/data/ies/asymmetric-full.ies"))}}};
        std::vector<std::unique_ptr<Scene>> scenes;
        for (const auto& [name, light] : lights) {
            SceneDescription d = base;
            d.lights[0] = light;
            scenes.push_back(Scene::build(d));
        }
        std::vector<std::vector<double>> t(scenes.size());
        for (int r = 0; r < o.repeats; ++r)
            for (size_t v = 0; v < scenes.size(); ++v) t[v].push_back(us_per_sample(*scenes[v], "pt-mis", o, uint64_t(r + 1)));
        for (size_t v = 0; v < scenes.size(); ++v)
            fmt::print("| {} | {:.3f} | {:.2f} |\n", lights[v].first, median(t[v]), median(t[v]) / median(t[0]));
    }
    fmt::print("\n");
}

}  // namespace pathlab::bench
