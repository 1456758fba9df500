// `pathlab report --scene S --algorithms a,b,c (--time T | --spp N) -o report.html`.
#include <tbb/global_control.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "app/interrupt.hpp"
#include "app/command_arguments.hpp"
#include "app/tool_commands.hpp"
#include "job/usage_error.hpp"
#include "image/image_io.hpp"
#include "job/output_paths.hpp"
#include "job/render_job.hpp"
#include "scene/builtin_scenes.hpp"
#include "judge/html_report.hpp"
#include "judge/image_compare.hpp"
#include "judge/reference_set.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

constexpr double kCheckpointGrowth = 1.25;  // checkpoints at geometrically spaced times

bool is_direct_illumination(const IntegratorInfo& e) { return e.name.rfind("direct-", 0) == 0; }

std::string command_line(const ReportOptions& o) {
    std::string s = fmt::format("pathlab report --scene {} --algorithms {}", o.scene, fmt::join(o.algorithms, ","));
    s += o.time_limit > 0 ? fmt::format(" --time {}", o.time_limit) : fmt::format(" --spp {}", o.spp);
    if (!o.resolution.empty()) s += " --resolution " + o.resolution;
    if (!o.reference.empty()) s += " --reference " + o.reference;
    else s += fmt::format(" --reference-spp {}", o.reference_spp) +
              (o.reference_algorithm != "pt-mis" ? " --reference-algorithm " + o.reference_algorithm : "");
    if (o.max_depth != -1) s += fmt::format(" --max-depth {}", o.max_depth);
    return s + fmt::format(" --seed {} -o {}", o.seed, o.output);
}

}  // namespace

CLI::App* add_report_command(CLI::App& app, ReportOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "report", "Equal-time (or equal-spp) comparison of estimators on one scene as an HTML page: images, errors, convergence plot");
    cmd->add_option("-s,--scene", o.scene, "Built-in scene (index or name) or a scene file (.xml)")->required();
    cmd->add_option("--algorithms", o.algorithms, "Estimators to compare, comma-separated (see `pathlab algorithms`)")
        ->required()
        ->delimiter(',');
    cmd->add_option("--time", o.time_limit, "Equal time: seconds per algorithm");
    cmd->add_option("--spp", o.spp, "Equal samples per pixel");
    cmd->add_option("-o,--output", o.output, "The HTML file; its images go to <name>_files/ beside it")->required();
    cmd->add_option("--reference", o.reference,
                    "Reference image (.exr/.hdr/.pfm; a .stderr.exr companion is used if present). Default: rendered "
                    "with pt-mis (--max-depth 1 when every algorithm is direct-*), saved beside the report for reuse");
    cmd->add_option("--reference-spp", o.reference_spp, "Samples per pixel of the rendered reference")->capture_default_str();
    cmd->add_option("--reference-algorithm", o.reference_algorithm,
                    "The estimator that renders the reference (e.g. vcm where pt-mis misses specular-diffuse-specular light)")
        ->capture_default_str();
    cmd->add_option("--resolution", o.resolution, "Image size WxH (default: the reference's, else the scene's)");
    cmd->add_option("--seed", o.seed, "Random seed of the compared renders")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path in bounces (-1: unlimited)")->capture_default_str();
    add_threads_option(*cmd, o.threads);
    cmd->add_flag("-q,--quiet", o.quiet, "No progress line and no summary");
    return cmd;
}

int run_report_command(const ReportOptions& o) {
    // Validate everything before the first render.
    const uint64_t seed = parse_seed_option(o.seed);
    if (o.scene == "all" || o.scene.find(',') != std::string::npos) throw UsageError("report takes one --scene");
    std::vector<SceneChoice> scenes = resolve_scenes(o.scene);
    const SceneChoice choice = std::move(scenes.front());
    std::vector<const IntegratorInfo*> infos;
    for (const std::string& a : o.algorithms) {
        const IntegratorInfo* e = &integrator_or_usage_error(a);
        if (std::find(infos.begin(), infos.end(), e) != infos.end()) throw UsageError(fmt::format("algorithm '{}' is listed twice", a));
        infos.push_back(e);
    }
    if (infos.empty()) throw UsageError("--algorithms needs at least one estimator");
    if ((o.time_limit > 0) == (o.spp > 0)) throw UsageError("give exactly one of --time T (equal time) and --spp N (equal samples)");
    if (o.time_limit < 0 || o.spp < 0 || !std::isfinite(o.time_limit)) throw UsageError("--time and --spp must be positive");
    if (o.reference_spp <= 0) throw UsageError("--reference-spp must be positive");
    const std::string reference_algorithm = integrator_or_usage_error(o.reference_algorithm).name;
    if (o.max_depth < -1 || o.max_depth == 0) throw UsageError("--max-depth must be positive, or -1 for unlimited");
    int width = 0, height = 0;
    parse_resolution_option(o.resolution, width, height);
    const size_t direct = size_t(std::count_if(infos.begin(), infos.end(), [](const IntegratorInfo* e) { return is_direct_illumination(*e); }));
    const bool all_direct = direct == infos.size();
    if (o.reference.empty() && direct > 0 && !all_direct)
        throw UsageError("direct-illumination and global estimators converge to different images: compare them separately, "
                         "or give --reference");
    if (fs::path(o.output).extension() != ".html") throw UsageError(fmt::format("-o {}: the report is an .html file", o.output));
    OutputPaths paths;
    if (!choice.file.empty()) paths.input(choice.file, "the scene file");
    if (!o.reference.empty()) {
        paths.input(o.reference, "--reference");
        paths.input(stderr_path_for(o.reference), "the reference's standard errors");
    }
    paths.output(o.output, "-o", /*image=*/false);
    paths.output((fs::path(o.output).replace_extension(".png")).string(), "the report's picture", /*image=*/true);
    try {
        check_writable_image_path((fs::path(report_files_dir(o.output)) / "probe.png").string());
    } catch (const ImageIoError& e) {
        throw UsageError(fmt::format("-o {}: {}", o.output, e.what()));
    }

    ReportData data;
    if (!o.reference.empty()) {
        try {
            data.reference = read_image(o.reference);
            if (fs::exists(stderr_path_for(o.reference))) data.reference_se = read_image(stderr_path_for(o.reference));
        } catch (const ImageIoError& e) {
            throw UsageError(e.what());
        }
        if (width == 0) width = data.reference.width(), height = data.reference.height();
        if (width != data.reference.width() || height != data.reference.height())
            throw UsageError(fmt::format("--resolution {}x{} differs from the reference {} ({}x{})", width, height, o.reference,
                                         data.reference.width(), data.reference.height()));
        if (data.reference_se.pixel_count() && data.reference_se.pixel_count() != data.reference.pixel_count())
            data.reference_se = Image();
        data.reference_label = fs::path(o.reference).filename().string();
        data.reference_note = fmt::format("{} (given){}", o.reference, data.reference_se.pixel_count() ? ", with its standard errors" : "");
    }

    std::optional<tbb::global_control> thread_limit;
    if (o.threads != 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, thread_count_or_cap(o.threads));
    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);
    data.title = choice.builtin ? fmt::format("scene {} {}", *choice.builtin, choice.name) : fmt::format("{} ({})", choice.name, choice.file);
    data.budget = o.time_limit > 0 ? fmt::format("equal time: {} s per algorithm", o.time_limit)
                                   : fmt::format("equal samples: {} spp per algorithm", o.spp);
    data.command = command_line(o);

    InterruptGuard interrupt;
    bool interrupted = false;
    if (data.reference.pixel_count() == 0) {
        JobRequest ref_request;
        ref_request.algorithm = reference_algorithm;
        ref_request.max_depth = all_direct ? 1 : o.max_depth;
        ref_request.width = width;
        ref_request.height = height;
        ref_request.spp = uint64_t(o.reference_spp);
        ref_request.seed = seed + 1000003;  // independent of the compared renders
        RenderJob ref_job(choice, ref_request);
        ref_job.settings.progress = show_progress;
        ref_job.settings.cancel = &InterruptGuard::flag();
        if (!o.quiet) fmt::print(stderr, "reference: {} at {} spp\n", reference_algorithm, o.reference_spp);
        const RenderResult r = ref_job.run();
        data.reference = r.film.mean();
        data.reference_se = r.film.standard_error();
        const std::string saved = (fs::path(report_files_dir(o.output)) / "reference.exr").string();
        write_image(data.reference, saved);
        write_image(data.reference_se, stderr_path_for(saved));
        data.reference_note = fmt::format("none given, so rendered here with {}{} at {} spp in {:.1f} s (saved as {}; reuse it with --reference)",
                                          reference_algorithm, all_direct ? " --max-depth 1 (direct illumination)" : "",
                                          r.stats.spp, r.stats.seconds, saved);
        data.reference_label = fmt::format("{}{}, {} spp", reference_algorithm, all_direct ? " (direct)" : "", r.stats.spp);
        if (r.stats.interrupted) {
            interrupted = true;
            data.notes.push_back(fmt::format("Interrupted while rendering the reference (after {} spp): no algorithm was rendered.", r.stats.spp));
        }
    }

    for (const IntegratorInfo* e : infos) {
        if (interrupted) {
            data.notes.push_back(fmt::format("Interrupted: {} was not rendered.", e->name));
            continue;
        }
        JobRequest request;
        request.algorithm = e->name;
        request.max_depth = o.max_depth;
        request.width = data.reference.width();
        request.height = data.reference.height();
        if (o.spp > 0) request.spp = uint64_t(o.spp);
        request.time_limit = o.time_limit;
        request.seed = seed;
        RenderJob job(choice, request);
        ReportRender entry{e->name, {}, {}, {}};
        double next_checkpoint = 0;
        RenderSettings& rs = job.settings;
        rs.progress = show_progress;
        rs.cancel = &InterruptGuard::flag();
        rs.after_pass = [&](const Film& film, const RenderStats& st) {
            const bool last = (o.spp > 0 && st.spp >= uint64_t(o.spp)) || (o.time_limit > 0 && st.seconds >= o.time_limit);
            if (st.seconds < next_checkpoint && !last) return;
            entry.convergence.push_back({st.seconds, rmse_against_reference(film.mean(), data.reference, data.reference_se)});
            next_checkpoint = st.seconds * kCheckpointGrowth;
        };
        if (!o.quiet) fmt::print(stderr, "{}\n", e->name);
        const RenderResult r = job.run();
        entry.mean = r.film.mean();
        entry.stats = r.stats;
        // The final point, if the last pass did not make a checkpoint (the time budget ended it).
        if (entry.convergence.empty() || entry.convergence.back().first < r.stats.seconds)
            entry.convergence.push_back({r.stats.seconds, rmse_against_reference(entry.mean, data.reference, data.reference_se)});
        if (!o.quiet) fmt::print(stderr, "  {} spp in {:.2f} s, RMSE {:.4g}\n", r.stats.spp, r.stats.seconds, entry.convergence.back().second);
        if (r.stats.interrupted) {
            interrupted = true;
            data.notes.push_back(fmt::format("Interrupted: {} stopped after {} spp ({:.2f} s), so it is not an equal-{} comparison.",
                                             e->name, r.stats.spp, r.stats.seconds, o.time_limit > 0 ? "time" : "sample"));
        }
        data.renders.push_back(std::move(entry));
    }

    const std::vector<std::string> files = write_html_report(data, o.output);
    if (!o.quiet) fmt::print(stderr, "{} ({} files in {})\n", o.output, files.size() - 1, report_files_dir(o.output));
    return interrupted ? interrupted_exit_code() : 0;
}

}  // namespace pathlab
