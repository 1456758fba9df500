// `pathlab check --algorithm X --references DIR`: the course's grader, with noise accounted for,
// on built-in scenes and scene files.
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
#include "judge/reference_manifest.hpp"
#include "judge/reference_set.hpp"
#include "judge/specular_mask.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

// A scene's reference in the directory, read before anything renders.
struct SceneReference {
    std::optional<ReferenceFile> file;
    std::optional<ReferenceRecord> record;  // from the directory's manifest.json, if it lists the file
    std::optional<LoadedReference> loaded;
    std::string tried, unreadable;
};

}  // namespace

CLI::App* add_check_command(CLI::App& app, CheckOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "check", "Render scenes with an estimator and judge each against a reference: OK/FAIL/MISSING/BLACK-BY-DESIGN");
    cmd->add_option("-a,--algorithm", o.algorithm,
                    "Estimator to check (name or course alias, see `pathlab algorithms`), or a comma-separated list")
        ->required();
    cmd->add_option("--references,--reference", o.references,
                    "Directory of references: .exr/.pfm/.hdr (e.g. from `pathlab reference`, whose manifest.json is checked) or the "
                    "course's 8-bit .png (names: {index}-{scene}, {index}, {scene} or the course acronym; a scene file's: its "
                    "stem; see docs/judging.md)")
        ->required();
    cmd->add_option("--mapping", o.mapping, "File of 'scene = file' lines when the references are named otherwise");
    add_scene_arguments(*cmd, o.scenes);
    cmd->add_option("--spp", o.spp, "Samples per pixel")->capture_default_str();
    cmd->add_option("--resolution", o.resolution, "Image size WxH (default: the reference's)");
    cmd->add_option("--seed", o.seed, "Random seed (if a reference has the same one, the next is used)")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path in bounces (-1: unlimited; default: the scene file's, else -1)");
    add_threads_option(*cmd, o.threads);
    cmd->add_option("--json", o.json_path, "Also write the verdicts as JSON to this file");
    cmd->add_flag("-q,--quiet", o.quiet, "Only the per-scene verdicts");
    cmd->footer(kInterruptHelp);
    return cmd;
}

int run_check_command(const CheckOptions& o) {
    const std::vector<const IntegratorInfo*> algorithms = parse_algorithm_list(o.algorithm);
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
    const std::vector<SceneChoice> scenes = resolve_scene_arguments(o.scenes, "all");
    int width = 0, height = 0;
    parse_resolution_option(o.resolution, width, height);
    if (o.spp <= 0) throw UsageError(fmt::format("--spp must be a positive number of samples, got {}", o.spp));
    if (o.max_depth && (*o.max_depth < -1 || *o.max_depth == 0)) throw UsageError("--max-depth must be positive, or -1 for unlimited");
    if (!o.json_path.empty()) {
        // The references (every file of the directory) and the mapping are inputs: --json must
        // not overwrite them, and nothing is written before the verdicts are in.
        OutputPaths paths;
        for (const auto& entry : fs::directory_iterator(o.references))
            if (entry.is_regular_file()) paths.input(entry.path().string(), "a file of --references");
        if (!o.mapping.empty()) paths.input(o.mapping, "--mapping");
        paths.output(o.json_path, "--json", /*image=*/false);
    }

    // Every reference is found and read before the first render, and one of another scene, size
    // or family (by its manifest) is refused: an unreadable file is an ERROR verdict of its scene.
    std::vector<SceneReference> refs(scenes.size());
    for (size_t i = 0; i < scenes.size(); ++i) {
        const SceneChoice& s = scenes[i];
        SceneReference& ref = refs[i];
        ref.file = s.builtin ? find_reference(o.references, *s.builtin, mapping, &ref.tried)
                             : find_reference_named(o.references, s.name, &ref.tried);
        if (!ref.file) continue;
        if (ref.file->kind == ReferenceKind::Linear) {
            try {
                ref.record = find_reference_record(ref.file->path);
            } catch (const ManifestError& e) {
                throw UsageError(e.what());  // what the references are of is unknown: nothing can be judged
            }
        }
        try {
            ref.loaded = load_reference(*ref.file);
        } catch (const ImageIoError& e) {
            ref.unreadable = e.what();
        }
        if (ref.loaded && width > 0) {
            JobRequest sized;
            sized.width = width, sized.height = height;
            const RenderJob job(s, sized);  // the size a render of --resolution has
            if (ref.loaded->width() != job.width() || ref.loaded->height() != job.height())
                throw UsageError(fmt::format("{} is {}x{}, but --resolution asks for {}x{}: a reference of another size cannot judge the "
                                             "render (leave --resolution out to render at the reference's size)",
                                             ref.file->path, ref.loaded->width(), ref.loaded->height(), job.width(), job.height()));
        }
    }
    JobRequest request;
    request.spp = uint64_t(o.spp);
    request.max_depth = o.max_depth;
    request.seed = seed;
    for (const IntegratorInfo* info : algorithms)
        for (size_t i = 0; i < scenes.size(); ++i) {
            if (!refs[i].record || !refs[i].loaded) continue;
            request.algorithm = info->name;
            const RenderJob job(scenes[i], request);
            const std::string why = reference_mismatch(*refs[i].record, refs[i].file->path, scenes[i], job.family(),
                                                       refs[i].loaded->width(), refs[i].loaded->height());
            if (!why.empty()) throw UsageError(fmt::format("check {}: {}", info->name, why));
        }

    std::optional<tbb::global_control> thread_limit;
    limit_threads(thread_limit, o.threads);
    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);

    InterruptGuard interrupt;
    int failed = 0, compared = 0;
    nlohmann::json results = nlohmann::json::array();
    for (const IntegratorInfo* info : algorithms) {
        fmt::print("check {} at {} spp against {}\n", info->name, o.spp, o.references);
        request.algorithm = info->name;
        for (size_t i = 0; i < scenes.size(); ++i) {
            const SceneChoice& s = scenes[i];
            const SceneReference& ref = refs[i];
            RenderJob job(s, request);
            SceneVerdict v;
            const std::string reference_name = ref.file ? fs::path(ref.file->path).filename().string() : "-";
            double seconds = 0;
            if (info->blind_to_delta_lights && !job.scene().has_hittable_emitters()) {
                v = {Verdict::BlackByDesign, fmt::format("{} cannot sample point lights, the only lights here", info->name)};
            } else if (!ref.file) {
                v = {Verdict::Missing, "no reference: looked for " + ref.tried};
            } else if (!ref.loaded) {
                v = {Verdict::Error, ref.unreadable};
            } else {
                RenderSettings& rs = job.settings;
                rs.width = ref.loaded->width();
                rs.height = ref.loaded->height();
                if (ref.record && ref.record->seed == seed) ++rs.seed;  // independent of the reference's samples
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
                            : judge_render(r->film.mean(), r->film.standard_error(), *ref.loaded, left_out ? &black : nullptr);
                    if (left_out && v.verdict != Verdict::BlackByDesign)
                        v.detail += fmt::format("; {} pixels ({:.1f}%) left out: black by design for {} (their first surface is specular)",
                                                left_out, 100.0 * double(left_out) / double(black.size()), info->name);
                }
                if (v.verdict == Verdict::Ok || v.verdict == Verdict::Fail) ++compared;
            }
            if (v.verdict == Verdict::Fail || v.verdict == Verdict::Error) ++failed;
            fmt::print("{} {:<16} {:<16} {:<22} {}\n", s.builtin ? std::to_string(*s.builtin) : "-", s.name, verdict_name(v.verdict),
                       reference_name, v.detail);
            std::fflush(stdout);
            nlohmann::json entry = {{"scene", s.name}, {"algorithm", info->name}, {"verdict", verdict_name(v.verdict)},
                                    {"reference", ref.file ? ref.file->path : ""}, {"detail", v.detail}, {"seconds", seconds}};
            if (s.builtin) entry["index"] = *s.builtin;
            if (!s.file.empty()) entry["scene_file"] = s.file;
            results.push_back(entry);
        }
    }
    const bool ok = failed == 0 && compared > 0;
    if (!o.quiet)
        fmt::print("{}: {} compared, {} failed{}\n", ok ? "PASSED" : "FAILED", compared, failed,
                   compared == 0 && failed == 0 ? " (no scene had a reference)" : "");
    if (!o.json_path.empty()) {
        std::vector<std::string> names;
        for (const IntegratorInfo* info : algorithms) names.push_back(info->name);
        write_text_file(o.json_path, nlohmann::json{{"pathlab_version", PATHLAB_VERSION}, {"algorithm", fmt::format("{}", fmt::join(names, ","))},
                                                    {"spp", o.spp}, {"references", o.references}, {"scenes", results},
                                                    {"passed", ok}}.dump(2) + "\n");
    }
    return ok ? 0 : 1;
}

}  // namespace pathlab
