#include "app/render_command.hpp"

#include <tbb/global_control.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "app/command_arguments.hpp"
#include "app/interrupt.hpp"
#include "app/usage_error.hpp"
#include "image/image_io.hpp"
#include "job/renderer.hpp"
#include "scene/builtin_scenes.hpp"
#include "scenefile/scene_file.hpp"

#include <filesystem>

namespace pathlab {
namespace {

constexpr int kDefaultSpp = 64;
const char* const kDefaultOutputs[] = {"out/{index}-{scene}-{algorithm}.exr", "out/{index}-{scene}-{algorithm}.png"};

struct SceneJob {
    std::string name;   // for {scene}
    std::string index;  // for {index}: the course index, or empty for scene files
    SceneDescription desc;
};


bool looks_like_scene_file(const std::string& key) {
    return key.size() > 4 && key.compare(key.size() - 4, 4, ".xml") == 0;
}

std::vector<SceneJob> resolve_scenes(const std::string& spec, const SceneDefines& defines) {
    std::vector<SceneJob> jobs;
    const auto add_builtin = [&](int i) {
        jobs.push_back({builtin_scenes()[size_t(i)].name, std::to_string(i), make_builtin_scene(i)});
    };
    if (spec == "all") {
        for (const BuiltinSceneInfo& s : builtin_scenes()) add_builtin(s.index);
        return jobs;
    }
    for (const std::string& key : split_comma_list(spec)) {
        if (looks_like_scene_file(key)) {
            // Scene-file errors (file:line:column) are usage errors: exit code 2.
            try {
                const std::string stem = std::filesystem::path(key).stem().string();
                jobs.push_back({stem, stem, load_scene_file(key, defines)});
            } catch (const SceneFileError& e) {
                throw UsageError(e.what());
            }
        } else {
            add_builtin(builtin_scene_or_usage_error(key, /*scene_files_allowed=*/true));
        }
    }
    return jobs;
}

std::string expand_output(const std::string& pattern, const SceneJob& job, const std::string& algorithm) {
    return fmt::format(fmt::runtime(pattern), fmt::arg("scene", job.name), fmt::arg("index", job.index),
                       fmt::arg("algorithm", algorithm));
}

void write_stats(const std::string& path, const SceneJob& job, const std::string& algorithm, const RenderSettings& rs,
                 const RenderResult& r, const std::vector<std::string>& outputs, int threads) {
    const RenderStats& s = r.stats;
    nlohmann::json j = {
        {"pathlab_version", PATHLAB_VERSION},
        {"scene", job.name},
        {"algorithm", algorithm},
        {"resolution", {r.film.width(), r.film.height()}},
        {"spp", s.spp},
        {"seed", rs.seed},
        {"sampler", rs.sampler == SamplerKind::Sobol ? "sobol" : "independent"},
        {"threads", threads},
        {"seconds", s.seconds},
        {"samples", s.samples},
        {"samples_per_second", s.seconds > 0 ? double(s.samples) / s.seconds : 0.0},
        {"rays", s.rays},
        {"rays_per_second", s.seconds > 0 ? double(s.rays) / s.seconds : 0.0},
        {"invalid_samples", s.invalid_samples},
        {"interrupted", s.interrupted},
        {"outputs", outputs},
    };
    write_text_file(path, j.dump(2) + "\n");
}

}  // namespace

void add_render_options(CLI::App& app, RenderCommandOptions& o) {
    app.add_option("-s,--scene", o.scene,
                   "Scene: course index 0-7, name (see `pathlab scenes`), a scene file (.xml), a comma-separated list, or 'all'")
        ->capture_default_str();
    app.add_option_function<std::string>(
        "-a,--algorithm", [&o](const std::string& v) { o.algorithm = v, o.algorithm_given = true; },
        "Estimator name or course alias (see `pathlab algorithms`); default: the scene file's integrator, else pt-mis");
    app.add_option("-D,--define", o.defines, "name=value for $name in scene files (repeatable; overrides <default>)");
    app.add_option_function<int>("--spp", [&o](const int& v) { o.spp = v, o.spp_given = true; },
                                 fmt::format("Samples per pixel (default {}, or unlimited with --time)", kDefaultSpp));
    app.add_option("--time", o.time_limit, "Time budget in seconds per scene (stops at --spp if that comes first)");
    app.add_option("--resolution", o.resolution, "Image size WxH (default: the scene's, 512x512 for the course)");
    app.add_option("--seed", o.seed, "Random seed; the image is a pure function of it")->capture_default_str();
    app.add_option("--sampler", o.sampler,
                   "Random numbers: 'independent' (PCG32; the course's setting, exact per-pixel standard errors) or "
                   "'sobol' (scrambled low-discrepancy points: lower error at equal time)")
        ->capture_default_str();
    app.add_option("--threads", o.threads, "Worker threads (default: all cores)");
    app.add_option("-o,--output", o.outputs,
                   "Output file, repeatable; format by extension: .exr .hdr .pfm .png. Placeholders {scene} {index} "
                   "{algorithm}. Default: out/{index}-{scene}-{algorithm}.exr and .png");
    app.add_option("--exposure", o.exposure, "Exposure in stops for .png output")->capture_default_str();
    app.add_option("--stats", o.stats_path, "Write render statistics as JSON (placeholders as for -o)");
    app.add_option_function<int>("--max-depth", [&o](const int& v) { o.max_depth = v, o.max_depth_given = true; },
                                 "Longest path in bounces (-1: unlimited; default: the scene file's, else -1)");
    app.add_option("--rr-depth", o.rr_depth, "Bounces before Russian roulette starts")->capture_default_str();
    app.add_flag("-q,--quiet", o.quiet, "No progress line and no summary");
}

int run_render_command(const RenderCommandOptions& o) {
    if (o.algorithm_given) estimator_or_usage_error(o.algorithm);
    SceneDefines defines;
    for (const std::string& d : o.defines) {
        const size_t eq = d.find('=');
        if (eq == std::string::npos || eq == 0)
            throw UsageError(fmt::format("invalid -D '{}': expected name=value", d));
        defines[d.substr(0, eq)] = d.substr(eq + 1);
    }
    std::vector<SceneJob> jobs = resolve_scenes(o.scene, defines);
    // Each job's estimator: --algorithm, else the scene file's integrator, else pt-mis.
    std::vector<const EstimatorInfo*> job_estimators;
    for (const SceneJob& job : jobs) {
        const std::string name = o.algorithm_given ? o.algorithm : job.desc.algorithm.value_or(o.algorithm);
        job_estimators.push_back(&estimator_or_usage_error(name));
    }

    int width = 0, height = 0;
    parse_resolution_option(o.resolution, width, height);
    if (o.spp_given && o.spp <= 0) throw UsageError(fmt::format("--spp must be a positive number of samples, got {}", o.spp));
    if (o.time_limit < 0 || !std::isfinite(o.time_limit)) throw UsageError("--time must be a positive number of seconds");
    if (o.threads < 0) throw UsageError("--threads must be positive");
    if (o.sampler != "independent" && o.sampler != "sobol")
        throw UsageError(fmt::format("unknown sampler '{}'. Valid samplers: independent, sobol", o.sampler));
    if (o.rr_depth < 0) throw UsageError("--rr-depth must be zero or positive");
    if (o.max_depth < -1 || o.max_depth == 0) throw UsageError("--max-depth must be positive, or -1 for unlimited");

    std::vector<std::string> patterns(o.outputs.begin(), o.outputs.end());
    if (patterns.empty()) patterns.assign(std::begin(kDefaultOutputs), std::end(kDefaultOutputs));
    // Check every output before the first render starts.
    std::vector<std::vector<std::string>> outputs(jobs.size());
    for (size_t j = 0; j < jobs.size(); ++j) {
        for (const std::string& p : patterns) {
            std::string path;
            try {
                path = expand_output(p, jobs[j], job_estimators[j]->name);
            } catch (const fmt::format_error& e) {
                throw UsageError(fmt::format("invalid output pattern '{}': {} (placeholders: {{scene}}, {{index}}, {{algorithm}})", p, e.what()));
            }
            try {
                check_writable_image_path(path);
            } catch (const ImageIoError& e) {
                throw UsageError(e.what());
            }
            outputs[j].push_back(path);
        }
        for (size_t k = 0; k < j; ++k)
            for (const std::string& path : outputs[j])
                if (std::find(outputs[k].begin(), outputs[k].end(), path) != outputs[k].end())
                    throw UsageError(fmt::format("scenes {} and {} would both write {}: add {{scene}} or {{index}} to -o",
                                                 jobs[k].name, jobs[j].name, path));
    }

    std::optional<tbb::global_control> thread_limit;
    if (o.threads > 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(o.threads));
    const int threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);

    InterruptGuard interrupt;
    for (size_t j = 0; j < jobs.size(); ++j) {
        const SceneJob& job = jobs[j];
        const EstimatorInfo* est_info = job_estimators[j];
        EstimatorOptions est_opt;
        est_opt.max_depth = o.max_depth_given ? o.max_depth : job.desc.max_depth.value_or(o.max_depth);
        est_opt.rr_depth = o.rr_depth;
        const std::unique_ptr<Estimator> estimator = est_info->make(est_opt);
        const std::unique_ptr<Scene> scene = Scene::build(job.desc);
        RenderSettings rs;
        rs.width = width;
        rs.height = height;
        // --spp, else (without --time) the scene file's sample_count, else 64.
        rs.spp = o.spp_given ? o.spp : (o.time_limit > 0 ? 0 : job.desc.spp.value_or(kDefaultSpp));
        rs.time_limit = o.time_limit;
        rs.seed = o.seed;
        rs.sampler = o.sampler == "sobol" ? SamplerKind::Sobol : SamplerKind::Independent;
        rs.progress = show_progress;
        rs.cancel = &InterruptGuard::flag();
        if (show_progress) fmt::print(stderr, "{} / {}\n", job.name, est_info->name);
        const RenderResult result = render(*scene, *estimator, rs);

        const Image image = result.film.mean();
        for (const std::string& path : outputs[j]) write_image(image, path, o.exposure);
        if (!o.stats_path.empty())
            write_stats(expand_output(o.stats_path, job, est_info->name), job, est_info->name, rs, result, outputs[j], threads);
        const RenderStats& s = result.stats;
        if (!o.quiet)
            fmt::print(stderr, "{}: {} spp in {:.2f}s ({:.2f} Msamples/s, {:.2f} Mrays/s){} -> {}\n", job.name, s.spp,
                       s.seconds, s.seconds > 0 ? s.samples / s.seconds * 1e-6 : 0.0,
                       s.seconds > 0 ? s.rays / s.seconds * 1e-6 : 0.0,
                       s.invalid_samples ? fmt::format(", {} NaN/Inf samples discarded", s.invalid_samples) : "",
                       fmt::join(outputs[j], ", "));
        if (s.interrupted) {
            if (j + 1 < jobs.size()) fmt::print(stderr, "pathlab: interrupted; {} scene(s) not rendered\n", jobs.size() - j - 1);
            return 130;
        }
    }
    return 0;
}

}  // namespace pathlab
