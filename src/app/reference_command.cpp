// `pathlab reference --out DIR`: reference images of built-in scenes and scene files, and their manifest.
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
#include "job/output_paths.hpp"
#include "judge/reference_manifest.hpp"
#include "judge/reference_set.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

constexpr int kDefaultReferenceSpp = 1024;

// The file stem of a scene's reference: "{index}-{scene}" for a built-in scene (what check
// looks for first), the scene file's stem for a file.
std::string reference_stem(const SceneChoice& s) { return s.builtin ? fmt::format("{}-{}", *s.builtin, s.name) : s.name; }

}  // namespace

CLI::App* add_reference_command(CLI::App& app, ReferenceOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "reference", "Render reference images (EXR + standard errors + PNG preview) and a manifest.json recording what they are of");
    cmd->add_option("-o,--out", o.out_dir,
                    "Directory for the references ({index}-{scene}.exr or, for a scene file, {scene}.exr, with .stderr.exr, .png, "
                    "and manifest.json); may hold {algorithm}, which several algorithms need")
        ->required();
    add_scene_arguments(*cmd, o.scenes);
    cmd->add_option("-a,--algorithm", o.algorithm,
                    "Estimator, or a comma-separated list (pt-mis: global illumination; direct-mis or pt-mis with --max-depth 1: "
                    "direct illumination)")
        ->capture_default_str();
    cmd->add_option("--spp", o.spp, fmt::format("Samples per pixel (default {}, or unlimited with --time)", kDefaultReferenceSpp));
    cmd->add_option("--time", o.time_limit, "Time budget in seconds per scene (with --spp, whichever ends first)");
    cmd->add_option("--resolution", o.resolution, "Image size WxH (default: the scene's, 512x512)");
    cmd->add_option("--seed", o.seed, "Random seed (differs from the renderer's default, so that checks are independent)")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path in bounces (-1: unlimited; default: the scene file's, else -1)");
    add_threads_option(*cmd, o.threads);
    cmd->add_flag("-q,--quiet", o.quiet, "No progress line and no summary");
    cmd->footer(kInterruptHelp);
    return cmd;
}

int run_reference_command(const ReferenceOptions& o) {
    const std::vector<const IntegratorInfo*> algorithms = parse_algorithm_list(o.algorithm);
    const uint64_t seed = parse_seed_option(o.seed);
    int width = 0, height = 0;
    parse_resolution_option(o.resolution, width, height);
    if (o.spp < 0) throw UsageError(fmt::format("--spp must be a positive number of samples, got {}", o.spp));
    if (o.time_limit < 0 || !std::isfinite(o.time_limit)) throw UsageError("--time must be a positive number of seconds");
    if (o.max_depth && (*o.max_depth < -1 || *o.max_depth == 0)) throw UsageError("--max-depth must be positive, or -1 for unlimited");
    if (algorithms.size() > 1 && o.out_dir.find("{algorithm}") == std::string::npos)
        throw UsageError(fmt::format("--out {}: several algorithms need {{algorithm}} in the directory, e.g. refs/{{algorithm}}", o.out_dir));

    JobRequest request;
    if (o.spp > 0) request.spp = uint64_t(o.spp);
    request.default_spp = kDefaultReferenceSpp;
    request.max_depth = o.max_depth;
    request.width = width;
    request.height = height;
    request.time_limit = o.time_limit;
    request.seed = seed;
    const std::vector<SceneChoice> scenes = resolve_scene_arguments(o.scenes, "all");
    std::vector<RenderJob> jobs;
    std::vector<std::string> dirs, stems;
    OutputPaths paths;
    for (const SceneChoice& s : scenes)
        paths.scene_inputs(s);
    for (const IntegratorInfo* info : algorithms)
        for (const SceneChoice& s : scenes) {
            request.algorithm = info->name;
            jobs.emplace_back(s, request);
            const std::string dir = jobs.back().expand(o.out_dir), stem = reference_stem(s);
            for (size_t k = 0; k < dirs.size(); ++k)
                if (dirs[k] == dir && stems[k] == stem)
                    throw UsageError(fmt::format("two scenes would both write {}/{}.exr (give each scene once, and scene files of "
                                                 "different names)", dir, stem));
            try {
                check_writable_image_path((fs::path(dir) / "probe.exr").string());
            } catch (const ImageIoError& e) {
                throw UsageError(fmt::format("--out {}: {}", dir, e.what()));
            }
            try {
                check_manifest(dir);
            } catch (const ManifestError& e) {
                throw UsageError(e.what());
            }
            for (const char* suffix : {".exr", ".stderr.exr", ".png"})
                paths.output((fs::path(dir) / (stem + suffix)).string(), "a reference", /*image=*/true);
            dirs.push_back(dir);
            stems.push_back(stem);
        }

    std::optional<tbb::global_control> thread_limit;
    limit_threads(thread_limit, o.threads);
    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);

    InterruptGuard interrupt;
    for (size_t j = 0; j < jobs.size(); ++j) {
        RenderJob& job = jobs[j];
        const SceneChoice& s = job.scene_choice();
        const IntegratorInfo& info = job.integrator_info();
        job.settings.progress = show_progress;
        job.settings.cancel = &InterruptGuard::flag();
        if (show_progress) fmt::print(stderr, "{} / {}\n", s.name, info.name);
        const RenderResult r = job.run();

        const fs::path dir(dirs[j]);
        const std::string& stem = stems[j];
        const fs::path exr = dir / (stem + ".exr");
        write_image(r.film.mean(), exr.string());
        write_image(r.film.standard_error(), stderr_path_for(exr.string()));
        write_image(r.film.mean(), (dir / (stem + ".png")).string());

        ReferenceRecord record;
        record.file = stem + ".exr";
        record.scene = s.name;
        record.index = s.builtin;
        record.scene_file = s.file;
        record.scene_hash = s.hash;
        record.parameters = s.parameters;
        record.stderr_file = fs::path(stderr_path_for(exr.string())).filename().string();
        record.preview = stem + ".png";
        record.algorithm = info.name;
        record.family = job.family();
        record.max_depth = job.integrator_options().max_depth;
        record.width = r.film.width();
        record.height = r.film.height();
        record.spp = r.stats.spp;
        record.seed = seed;
        record.seconds = r.stats.seconds;
        record.invalid_samples = r.stats.invalid_samples;
        record.interrupted = r.stats.interrupted;
        record_reference(dir.string(), record);
        if (!o.quiet)
            fmt::print(stderr, "{}: {} spp in {:.2f}s{} -> {}\n", stem, r.stats.spp, r.stats.seconds,
                       r.stats.interrupted ? " (interrupted)" : "", exr.string());
        if (r.stats.interrupted) return interrupted_exit_code();
    }
    return 0;
}

}  // namespace pathlab
