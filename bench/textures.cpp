// `pathlab_bench textures` (part of `make bench`): what textures cost.
//  1. Per pt-mis sample: course scene 2 (the diffuse Cornell box) as it is, and with each of
//     its materials' colours given by a 512 x 512 bilinear bitmap whose texels all hold that
//     colour (the same image bit for bit, so the difference is the texture path alone); and
//     scenes/textures.xml with its textures and maps, with its textures only, and with every
//     material constant (the textures' largest values). Interleaved rounds, medians, ns per
//     sample and the ratio to the constant scene, measured in one run.
//  2. Per lookup: bilinear and nearest bitmaps, the checkerboard, the scalar gradient (bump
//     maps), at random uv on one thread.
#include "textures.hpp"

#include <tbb/task_arena.h>

#include <chrono>
#include <cstdio>
#include <random>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::bench {
namespace {

// Every material's colours as bitmaps of n x n texels of the same value.
SceneDescription with_constant_bitmaps(SceneDescription d, int n) {
    for (Material& m : d.materials) {
        const auto* phong = std::get_if<PhongMaterial>(&m.model);
        if (!phong || m.is_black()) continue;
        MaterialTextures t;
        const auto bind = [&](int slot, const char* name, const Rgb& v) {
            auto tex = std::make_shared<const Texture>(BitmapTexture(n, n, std::vector<Rgb>(size_t(n) * size_t(n), v)));
            t.bindings.push_back({name, slot, false, std::move(tex)});
        };
        bind(PhongMaterial::kSlotDiffuse, "diffuse_reflectance", phong->diffuse);
        if (!is_black(phong->specular)) bind(PhongMaterial::kSlotSpecular, "specular_reflectance", phong->specular);
        m.set_textures(std::move(t));
    }
    return d;
}

// The scene without its normal and bump maps (textures kept), or without anything that varies.
SceneDescription without(SceneDescription d, bool textures_too) {
    for (Material& m : d.materials) {
        if (!m.textures) continue;
        if (textures_too) {
            m.textures = nullptr;
            m.prepare();
            continue;
        }
        MaterialTextures t = *m.textures;
        t.perturbation = FramePerturbation::None;
        t.perturbation_texture = nullptr;
        if (t.bindings.empty()) {
            m.textures = nullptr;
            m.prepare();
        } else {
            m.set_textures(std::move(t));
        }
    }
    return d;
}

struct Variant {
    std::string name;
    std::unique_ptr<Scene> scene;
};

void per_sample_table(const std::string& title, std::vector<Variant> variants, const TexturesOptions& o) {
    std::vector<std::vector<double>> ns(variants.size());
    for (int k = 0; k < o.repeats; ++k)
        for (size_t v = 0; v < variants.size(); ++v) {
            const RenderResult r = run(*variants[v].scene, "pt-mis", o.size, 0, o.seconds, 100 + uint64_t(k));
            ns[v].push_back(r.stats.seconds * 1e9 / double(std::max<uint64_t>(1, r.stats.samples)));
        }
    fmt::print("| {} | ns per sample | / constant |\n|---|---|---|\n", title);
    const double base = median(ns[0]);
    for (size_t v = 0; v < variants.size(); ++v)
        fmt::print("| {} | {:.0f} | {:.3f} |\n", variants[v].name, median(ns[v]), median(ns[v]) / base);
    fmt::print("\n");
    std::fflush(stdout);
}

template <typename F>
double ns_per_call(int n, F&& f) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-2.0f, 3.0f);
    std::vector<Vec2f> uv(4096);
    for (Vec2f& x : uv) x = Vec2f(u(rng), u(rng));
    float sink = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i) sink += f(uv[size_t(i) & 4095]);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (sink == 1234.5f) std::puts("");  // keeps the calls
    return s * 1e9 / n;
}

}  // namespace

void textures_suite(const TexturesOptions& o) {
    const int threads = std::min(2, tbb::this_task_arena::max_concurrency());
    fmt::print("## Textures: pt-mis cost per sample, {0}x{0}, {1} threads, {2} s per render, medians of {3} interleaved rounds\n\n",
               o.size, threads, o.seconds, o.repeats);
    {
        const SceneDescription box = make_builtin_scene(2);
        std::vector<Variant> v;
        v.push_back({"scene 2, constant colours", Scene::build(box)});
        v.push_back({"scene 2, the same colours as 512x512 bitmaps", Scene::build(with_constant_bitmaps(box, 512))});
        per_sample_table("course scene 2 (diffuse box)", std::move(v), o);
    }
    {
        const std::string file = o.scene_file.empty() ? std::string(PATHLAB_SOURCE_DIR) + "/scenes/textures.xml" : o.scene_file;
        const SceneDescription d = load_scene_file(file);
        std::vector<Variant> v;
        v.push_back({"every material constant", Scene::build(without(d, true))});
        v.push_back({"textures, no normal or bump maps", Scene::build(without(d, false))});
        v.push_back({"textures, normal and bump maps", Scene::build(d)});
        per_sample_table("scenes/textures.xml", std::move(v), o);
    }

    fmt::print("## Texture lookups (one thread, random uv in [-2, 3)^2, {} lookups each)\n\n| lookup | ns |\n|---|---|\n", o.lookups);
    std::vector<Rgb> texels(512 * 512);
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> c(0, 1);
    for (Rgb& t : texels) t = Rgb(c(rng), c(rng), c(rng));
    const BitmapTexture bilinear(512, 512, texels), nearest(512, 512, texels, FilterType::Nearest);
    const BitmapTexture mirror(512, 512, texels, FilterType::Bilinear, WrapMode::Mirror);
    CheckerboardTexture checker;
    checker.to_uv = UvTransform::from(Transform::scale({8, 8, 1}));
    const Texture wrapped(bilinear);
    fmt::print("| bitmap 512x512 bilinear, repeat | {:.1f} |\n", ns_per_call(o.lookups, [&](Vec2f uv) { return bilinear.eval(uv).x; }));
    fmt::print("| bitmap 512x512 bilinear, mirror | {:.1f} |\n", ns_per_call(o.lookups, [&](Vec2f uv) { return mirror.eval(uv).x; }));
    fmt::print("| bitmap 512x512 nearest | {:.1f} |\n", ns_per_call(o.lookups, [&](Vec2f uv) { return nearest.eval(uv).x; }));
    fmt::print("| bitmap through Texture (std::visit) | {:.1f} |\n", ns_per_call(o.lookups, [&](Vec2f uv) { return wrapped.eval(uv).x; }));
    fmt::print("| bitmap scalar gradient (bump map) | {:.1f} |\n",
               ns_per_call(o.lookups, [&](Vec2f uv) { return bilinear.eval_1_grad(uv).x; }));
    fmt::print("| bitmap footprint (texels and weights) | {:.1f} |\n",
               ns_per_call(o.lookups, [&](Vec2f uv) { return bilinear.footprint(uv).weight[1]; }));
    fmt::print("| checkerboard | {:.1f} |\n\n", ns_per_call(o.lookups, [&](Vec2f uv) { return checker.eval(uv).x; }));
    std::fflush(stdout);
}

}  // namespace pathlab::bench
