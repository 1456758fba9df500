// `pathlab check --algorithm X --references DIR`: the course's grader, with noise accounted for.
#include <tbb/global_control.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "app/interrupt.hpp"
#include "app/command_arguments.hpp"
#include "app/tool_commands.hpp"
#include "job/usage_error.hpp"
#include "image/image_io.hpp"
#include "job/output_paths.hpp"
#include "job/render_job.hpp"
#include "scene/builtin_scenes.hpp"
#include "judge/check.hpp"
#include "judge/reference_set.hpp"
#include "judge/specular_mask.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

// Seeds of the references, from a manifest.json written by `pathlab reference` (if any).
std::map<int, uint64_t> reference_seeds(const std::string& dir) {
    std::map<int, uint64_t> seeds;
    const fs::path path = fs::path(dir) / "manifest.json";
    if (!fs::exists(path)) return seeds;
    try {
        const nlohmann::json j = nlohmann::json::parse(std::ifstream(path));
        for (const nlohmann::json& e : j.at("scenes"))
            if (e.contains("index") && e.contains("seed")) seeds[e["index"].get<int>()] = e["seed"].get<uint64_t>();
    } catch (const nlohmann::json::exception&) {
    }
    return seeds;
}

}  // namespace

CLI::App* add_check_command(CLI::App& app, CheckOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "check", "Render the built-in scenes with an estimator and judge each against a reference: OK/FAIL/MISSING/BLACK-BY-DESIGN");
    cmd->add_option("-a,--algorithm", o.algorithm, "Estimator to check (name or course alias, see `pathlab algorithms`)")->required();
    cmd->add_option("--references", o.references,
                    "Directory of references: .exr/.pfm/.hdr (e.g. from `pathlab reference`) or the course's 8-bit .png "
                    "(names: {index}-{scene}, {index}, {scene} or the course acronym; see README)")
        ->required();
    cmd->add_option("--mapping", o.mapping, "File of 'scene = file' lines when the references are named otherwise");
    cmd->add_option("-s,--scene", o.scenes, "Scenes: 'all' or a comma-separated list of indices or names")->capture_default_str();
    cmd->add_option("--spp", o.spp, "Samples per pixel")->capture_default_str();
    cmd->add_option("--resolution", o.resolution, "Image size WxH (default: the reference's)");
    cmd->add_option("--seed", o.seed, "Random seed (if a reference has the same one, the next is used)")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path in bounces (-1: unlimited)")->capture_default_str();
    add_threads_option(*cmd, o.threads);
    cmd->add_option("--json", o.json_path, "Also write the verdicts as JSON to this file");
    cmd->add_flag("-q,--quiet", o.quiet, "Only the per-scene verdicts");
    return cmd;
}

int run_check_command(const CheckOptions& o) {
    const IntegratorInfo* info = &integrator_or_usage_error(o.algorithm);
    const uint64_t seed = parse_seed_option(o.seed);
    if (!fs::is_directory(o.references)) throw UsageError(fmt::format("--references {}: no such directory", o.references));
    std::map<int, std::string> mapping;
    if (!o.mapping.empty()) {
        try {
            mapping = read_reference_mapping(o.mapping);
        } catch (const ReferenceMappingError& e) {
            throw UsageError(e.what());
        }
    }
    const std::vector<int> scenes = parse_builtin_scene_list(o.scenes);
    int width = 0, height = 0;
    parse_resolution_option(o.resolution, width, height);
    if (o.spp <= 0) throw UsageError(fmt::format("--spp must be a positive number of samples, got {}", o.spp));
    if (o.max_depth < -1 || o.max_depth == 0) throw UsageError("--max-depth must be positive, or -1 for unlimited");
    if (!o.json_path.empty()) {
        // The references (every file of the directory) and the mapping are inputs: --json must
        // not overwrite them, and nothing is written before the verdicts are in.
        OutputPaths paths;
        for (const auto& entry : fs::directory_iterator(o.references))
            if (entry.is_regular_file()) paths.input(entry.path().string(), "a file of --references");
        if (!o.mapping.empty()) paths.input(o.mapping, "--mapping");
        paths.output(o.json_path, "--json", /*image=*/false);
    }

    std::optional<tbb::global_control> thread_limit;
    if (o.threads != 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, thread_count_or_cap(o.threads));
    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);
    const std::map<int, uint64_t> ref_seeds = reference_seeds(o.references);
    JobRequest request;
    request.algorithm = info->name;
    request.spp = uint64_t(o.spp);
    request.max_depth = o.max_depth;
    request.seed = seed;

    fmt::print("check {} at {} spp against {}\n", info->name, o.spp, o.references);
    InterruptGuard interrupt;
    int failed = 0, compared = 0;
    nlohmann::json results = nlohmann::json::array();
    for (const int index : scenes) {
        const BuiltinSceneInfo& s = builtin_scenes()[size_t(index)];
        RenderJob job(index, request);
        SceneVerdict v;
        std::string reference_name = "-";
        double seconds = 0;
        std::string tried;
        const std::optional<ReferenceFile> ref = find_reference(o.references, index, mapping, &tried);
        // Read before rendering: an unreadable reference is not worth a render, and its size is
        // the render's unless --resolution says otherwise.
        std::optional<LoadedReference> loaded;
        std::string unreadable;
        if (ref) {
            reference_name = fs::path(ref->path).filename().string();
            try {
                loaded = load_reference(*ref);
            } catch (const ImageIoError& e) {
                unreadable = e.what();
            }
        }
        if (info->blind_to_delta_lights && !job.scene().has_hittable_emitters()) {
            v = {Verdict::BlackByDesign, fmt::format("{} cannot sample point lights, the only lights here", info->name)};
        } else if (!ref) {
            v = {Verdict::Missing, "no reference: looked for " + tried};
        } else if (!loaded) {
            v = {Verdict::Error, unreadable};
        } else {
            RenderSettings& rs = job.settings;
            rs.width = width > 0 ? width : loaded->width();
            rs.height = height > 0 ? height : loaded->height();
            const auto it = ref_seeds.find(index);
            if (it != ref_seeds.end() && it->second == seed) ++rs.seed;  // independent of the reference's samples
            rs.progress = show_progress;
            rs.cancel = &InterruptGuard::flag();
            std::optional<RenderResult> r;
            try {
                r = job.run();
            } catch (const std::exception& e) {  // a film too large for memory: this scene fails, the others go on
                v = {Verdict::Error, e.what()};
            }
            if (r) {
                seconds = r->stats.seconds;
                if (r->stats.interrupted) {
                    fmt::print(stderr, "pathlab: interrupted\n");
                    return interrupted_exit_code();
                }
                // Pixels the integrator leaves black by design (a light tracer behind mirrors and glass).
                std::vector<uint8_t> black;
                if (!info->sees_specular_from_camera) black = specular_first_vertex_mask(job.scene(), rs.width, rs.height);
                const size_t left_out = count_marked(black);
                v = left_out == black.size() && left_out > 0
                        ? SceneVerdict{Verdict::BlackByDesign,
                                       fmt::format("{} sees no pixel: all show specular surfaces first", info->name)}
                        : judge_render(r->film.mean(), r->film.standard_error(), *loaded, left_out ? &black : nullptr);
                if (left_out && v.verdict != Verdict::BlackByDesign)
                    v.detail += fmt::format("; {} pixels ({:.1f}%) left out: black by design for {} (their first surface is specular)",
                                            left_out, 100.0 * double(left_out) / double(black.size()), info->name);
            }
            if (v.verdict == Verdict::Ok || v.verdict == Verdict::Fail) ++compared;
        }
        if (v.verdict == Verdict::Fail || v.verdict == Verdict::Error) ++failed;
        fmt::print("{} {:<16} {:<16} {:<22} {}\n", s.index, s.name, verdict_name(v.verdict), reference_name, v.detail);
        std::fflush(stdout);
        results.push_back({{"index", s.index}, {"scene", s.name}, {"verdict", verdict_name(v.verdict)},
                           {"reference", ref ? ref->path : ""}, {"detail", v.detail}, {"seconds", seconds}});
    }
    const bool ok = failed == 0 && compared > 0;
    if (!o.quiet)
        fmt::print("{}: {} compared, {} failed{}\n", ok ? "PASSED" : "FAILED", compared, failed,
                   compared == 0 && failed == 0 ? " (no scene had a reference)" : "");
    if (!o.json_path.empty())
        write_text_file(o.json_path, nlohmann::json{{"pathlab_version", PATHLAB_VERSION}, {"algorithm", info->name},
                                                    {"spp", o.spp}, {"references", o.references}, {"scenes", results},
                                                    {"passed", ok}}.dump(2) + "\n");
    return ok ? 0 : 1;
}

}  // namespace pathlab
