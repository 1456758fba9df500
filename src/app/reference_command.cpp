// `pathlab reference --out DIR`: the reference set of the built-in scenes.
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "app/interrupt.hpp"
#include "app/command_arguments.hpp"
#include "app/tool_commands.hpp"
#include "job/usage_error.hpp"
#include "image/image_io.hpp"
#include "job/render_job.hpp"
#include "scene/builtin_scenes.hpp"
#include "judge/reference_set.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

constexpr int kDefaultReferenceSpp = 1024;

std::string utc_now() {
    const std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return buf;
}

// The manifest's scene entries from an earlier run into the same directory (kept unless
// re-rendered now).
nlohmann::json previous_entries(const fs::path& manifest) {
    if (!fs::exists(manifest)) return nlohmann::json::array();
    try {
        const nlohmann::json j = nlohmann::json::parse(std::ifstream(manifest));
        if (j.contains("scenes") && j["scenes"].is_array()) return j["scenes"];
    } catch (const nlohmann::json::exception&) {
    }
    return nlohmann::json::array();
}

}  // namespace

CLI::App* add_reference_command(CLI::App& app, ReferenceOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "reference", "Render reference images of the built-in scenes (EXR + standard errors + PNG preview) and a manifest.json");
    cmd->add_option("--out", o.out_dir, "Directory for the references ({index}-{scene}.exr, .stderr.exr, .png, manifest.json)")->required();
    cmd->add_option("-s,--scene", o.scenes, "Scenes: 'all' or a comma-separated list of indices or names")->capture_default_str();
    cmd->add_option("-a,--algorithm", o.algorithm,
                    "Estimator (pt-mis: global illumination; direct-mis or pt-mis with --max-depth 1: direct illumination)")
        ->capture_default_str();
    cmd->add_option("--spp", o.spp, fmt::format("Samples per pixel (default {}, or unlimited with --time)", kDefaultReferenceSpp));
    cmd->add_option("--time", o.time_limit, "Time budget in seconds per scene (with --spp, whichever ends first)");
    cmd->add_option("--resolution", o.resolution, "Image size WxH (default: the scene's, 512x512)");
    cmd->add_option("--seed", o.seed, "Random seed (differs from the renderer's default, so that checks are independent)")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path in bounces (-1: unlimited)")->capture_default_str();
    add_threads_option(*cmd, o.threads);
    cmd->add_flag("-q,--quiet", o.quiet, "No progress line and no summary");
    return cmd;
}

int run_reference_command(const ReferenceOptions& o) {
    const IntegratorInfo* info = &integrator_or_usage_error(o.algorithm);
    const uint64_t seed = parse_seed_option(o.seed);
    const std::vector<int> scenes = parse_builtin_scene_list(o.scenes);
    int width = 0, height = 0;
    parse_resolution_option(o.resolution, width, height);
    if (o.spp < 0) throw UsageError(fmt::format("--spp must be a positive number of samples, got {}", o.spp));
    if (o.time_limit < 0 || !std::isfinite(o.time_limit)) throw UsageError("--time must be a positive number of seconds");
    if (o.max_depth < -1 || o.max_depth == 0) throw UsageError("--max-depth must be positive, or -1 for unlimited");
    const fs::path dir(o.out_dir);
    try {
        check_writable_image_path((dir / "probe.exr").string());
    } catch (const ImageIoError& e) {
        throw UsageError(fmt::format("--out {}: {}", o.out_dir, e.what()));
    }

    std::optional<tbb::global_control> thread_limit;
    if (o.threads != 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, thread_count_or_cap(o.threads));
    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);
    const fs::path manifest_path = dir / "manifest.json";
    nlohmann::json entries = previous_entries(manifest_path);

    InterruptGuard interrupt;
    JobRequest request;
    request.algorithm = info->name;
    if (o.spp > 0) request.spp = uint64_t(o.spp);
    request.default_spp = kDefaultReferenceSpp;
    request.max_depth = o.max_depth;
    request.width = width;
    request.height = height;
    request.time_limit = o.time_limit;
    request.seed = seed;
    for (const int index : scenes) {
        const BuiltinSceneInfo& s = builtin_scenes()[size_t(index)];
        RenderJob job(index, request);
        job.settings.progress = show_progress;
        job.settings.cancel = &InterruptGuard::flag();
        if (show_progress) fmt::print(stderr, "{} / {}\n", s.name, info->name);
        const RenderResult r = job.run();

        const std::string stem = fmt::format("{}-{}", s.index, s.name);
        const fs::path exr = dir / (stem + ".exr");
        write_image(r.film.mean(), exr.string());
        write_image(r.film.standard_error(), stderr_path_for(exr.string()));
        write_image(r.film.mean(), (dir / (stem + ".png")).string());

        for (auto it = entries.begin(); it != entries.end();)
            it = (it->is_object() && it->value("index", -1) == index) ? entries.erase(it) : it + 1;
        entries.push_back({{"index", s.index},
                           {"scene", s.name},
                           {"file", stem + ".exr"},
                           {"stderr_file", fs::path(stderr_path_for(exr.string())).filename().string()},
                           {"preview", stem + ".png"},
                           {"algorithm", info->name},
                           {"max_depth", o.max_depth},
                           {"resolution", {r.film.width(), r.film.height()}},
                           {"spp", r.stats.spp},
                           {"seed", seed},
                           {"seconds", r.stats.seconds},
                           {"invalid_samples", r.stats.invalid_samples},
                           {"interrupted", r.stats.interrupted},
                           {"created", utc_now()}});
        std::sort(entries.begin(), entries.end(),
                  [](const nlohmann::json& a, const nlohmann::json& b) { return a.value("index", 99) < b.value("index", 99); });
        const nlohmann::json manifest = {{"pathlab_version", PATHLAB_VERSION}, {"scenes", entries}};
        write_text_file(manifest_path.string(), manifest.dump(2) + "\n");
        if (!o.quiet)
            fmt::print(stderr, "{}: {} spp in {:.2f}s{} -> {}\n", stem, r.stats.spp, r.stats.seconds,
                       r.stats.interrupted ? " (interrupted)" : "", exr.string());
        if (r.stats.interrupted) return interrupted_exit_code();
    }
    return 0;
}

}  // namespace pathlab
