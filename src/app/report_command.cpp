// `pathlab report SCENE -a a,b,c (--time T | --spp N) -o report.html`: built-in scenes and scene
// files, one page per scene.
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
#include "cameras/camera.hpp"
#include "integrators/guiding/guide_map.hpp"
#include "integrators/guiding/ppg.hpp"
#include "judge/html_report.hpp"
#include "judge/image_compare.hpp"
#include "judge/reference_manifest.hpp"
#include "judge/reference_set.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

constexpr double kCheckpointGrowth = 1.25;  // checkpoints at geometrically spaced times

bool is_direct_illumination(const IntegratorInfo& e) { return e.name.rfind("direct-", 0) == 0; }

std::string command_line(const ReportOptions& o, const std::string& scene, const std::string& output, const std::string& reference) {
    std::string s = fmt::format("pathlab report {} -a {}", scene, o.algorithms);
    s += o.time_limit > 0 ? fmt::format(" --time {}", o.time_limit) : fmt::format(" --spp {}", o.spp);
    if (!o.resolution.empty()) s += " --resolution " + o.resolution;
    for (const std::string& d : o.scenes.defines) s += " -D " + d;
    if (!reference.empty()) s += " --reference " + reference;
    else s += fmt::format(" --reference-spp {}", o.reference_spp) +
              (o.reference_algorithm != "pt-mis" ? " --reference-algorithm " + o.reference_algorithm : "");
    if (o.max_depth) s += fmt::format(" --max-depth {}", *o.max_depth);
    for (const std::string& c : o.crops) s += " --crop " + c;
    if (!o.guide_pixel.empty()) s += " --guide-pixel " + o.guide_pixel;
    return s + fmt::format(" --seed {} -o {}", o.seed, output);
}

// One page of the report: a scene, where it goes, and its reference (given or to render).
struct PageJob {
    SceneChoice choice;
    std::string output;
    std::string reference;  // the given reference's path; empty: rendered here
};

std::string expand_scene(const std::string& pattern, const SceneChoice& s) {
    try {
        return fmt::format(fmt::runtime(pattern), fmt::arg("scene", s.name), fmt::arg("index", s.index));
    } catch (const fmt::format_error& e) {
        throw UsageError(fmt::format("invalid output pattern '{}': {} (placeholders: {{scene}}, {{index}})", pattern, e.what()));
    }
}

}  // namespace

CLI::App* add_report_command(CLI::App& app, ReportOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "report", "Equal-time (or equal-spp) comparison of estimators on a scene as an HTML page: images, errors, convergence plots");
    add_scene_arguments(*cmd, o.scenes);
    cmd->add_option("-a,--algorithm,--algorithms", o.algorithms, "Estimators to compare, comma-separated (see `pathlab algorithms`)")
        ->required();
    cmd->add_option("--time", o.time_limit, "Equal time: seconds per algorithm");
    cmd->add_option("--spp", o.spp, "Equal samples per pixel");
    cmd->add_option("-o,--output", o.output,
                    "The HTML file; its images go to <name>_files/ beside it (several scenes: put {scene} or {index} in it)")
        ->required();
    cmd->add_option("--reference,--references", o.reference,
                    "Reference image (.exr/.hdr/.pfm; a .stderr.exr companion is used if present, and refused if its manifest.json says "
                    "it is of another scene, size or estimator family), or a directory of references as `check` takes. Default: "
                    "rendered first with pt-mis (--max-depth 1 when every algorithm is direct-*), saved beside the report for reuse");
    cmd->add_option("--reference-spp", o.reference_spp, "Samples per pixel of the rendered reference")->capture_default_str();
    cmd->add_option("--reference-algorithm", o.reference_algorithm,
                    "The estimator that renders the reference (e.g. vcm where pt-mis misses specular-diffuse-specular light)")
        ->capture_default_str();
    cmd->add_option("--resolution", o.resolution, "Image size WxH (default: the reference's, else the scene's)");
    cmd->add_option("--seed", o.seed, "Random seed of the compared renders")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path in bounces (-1: unlimited; default: the scene file's, else -1)");
    cmd->add_option("--crop", o.crops, "An inset X,Y,W,H (pixels from the top left) shown magnified for every image (repeatable)");
    cmd->add_option("--guide-pixel", o.guide_pixel,
                    "ppg: also show the guiding distribution its SD-tree learned where the ray through the centre of pixel X,Y (from the "
                    "top left) first hits the scene, as an image of the sphere of directions");
    add_threads_option(*cmd, o.threads);
    cmd->add_flag("-q,--quiet", o.quiet, "No progress line and no summary");
    cmd->footer(kInterruptHelp);
    return cmd;
}

int run_report_command(const ReportOptions& o) {
    // Validate everything before the first render.
    const uint64_t seed = parse_seed_option(o.seed);
    const std::vector<const IntegratorInfo*> infos = parse_algorithm_list(o.algorithms);
    std::vector<SceneChoice> scenes = resolve_scene_arguments(o.scenes);
    if ((o.time_limit > 0) == (o.spp > 0)) throw UsageError("give exactly one of --time T (equal time) and --spp N (equal samples)");
    if (o.time_limit < 0 || o.spp < 0 || !std::isfinite(o.time_limit)) throw UsageError("--time and --spp must be positive");
    if (o.reference_spp <= 0) throw UsageError("--reference-spp must be positive");
    const std::string reference_algorithm = integrator_or_usage_error(o.reference_algorithm).name;
    if (o.max_depth && (*o.max_depth < -1 || *o.max_depth == 0)) throw UsageError("--max-depth must be positive, or -1 for unlimited");
    int width = 0, height = 0;
    parse_resolution_option(o.resolution, width, height);
    std::vector<PixelRect> crops;
    for (const std::string& c : o.crops) crops.push_back(parse_crop_option(c));
    std::optional<std::pair<int, int>> guide_pixel;
    if (!o.guide_pixel.empty()) {
        guide_pixel = parse_pixel_option(o.guide_pixel);
        if (std::none_of(infos.begin(), infos.end(), [](const IntegratorInfo* e) { return e->name == "ppg"; }))
            throw UsageError("--guide-pixel shows what ppg learned: add ppg to -a");
    }
    const size_t direct = size_t(std::count_if(infos.begin(), infos.end(), [](const IntegratorInfo* e) { return is_direct_illumination(*e); }));
    const bool all_direct = direct == infos.size();
    if (o.reference.empty() && direct > 0 && !all_direct)
        throw UsageError("direct-illumination and global estimators converge to different images: compare them separately, "
                         "or give --reference");
    if (fs::path(o.output).extension() != ".html") throw UsageError(fmt::format("-o {}: the report is an .html file", o.output));
    const bool reference_dir = !o.reference.empty() && fs::is_directory(o.reference);
    if (scenes.size() > 1 && !o.reference.empty() && !reference_dir)
        throw UsageError(fmt::format("--reference {} is one image, but {} scenes are reported: give a directory of references (as "
                                     "`pathlab reference` writes), or one scene",
                                     o.reference, scenes.size()));

    OutputPaths paths;
    std::vector<PageJob> pages;
    for (SceneChoice& choice : scenes) {
        std::string output = expand_scene(o.output, choice);
        PageJob page{std::move(choice), std::move(output), o.reference};
        for (const PageJob& other : pages)
            if (other.output == page.output)
                throw UsageError(fmt::format("scenes {} and {} would both write {}: add {{scene}} or {{index}} to -o", other.choice.name,
                                             page.choice.name, page.output));
        if (reference_dir) {
            std::string tried;
            const std::optional<ReferenceFile> found = page.choice.builtin ? find_reference(o.reference, *page.choice.builtin, {}, &tried)
                                                                           : find_reference_named(o.reference, page.choice.name, &tried);
            if (!found || found->kind != ReferenceKind::Linear)
                throw UsageError(fmt::format("--reference {}: no linear reference (.exr, .pfm, .hdr) of {}: looked for {}", o.reference,
                                             page.choice.name, tried));
            page.reference = found->path;
        }
        paths.scene_inputs(page.choice);
        if (!page.reference.empty()) {
            paths.input(page.reference, "--reference");
            paths.input(stderr_path_for(page.reference), "the reference's standard errors");
        }
        paths.output(page.output, "-o", /*image=*/false);
        paths.output((fs::path(page.output).replace_extension(".png")).string(), "the report's picture", /*image=*/true);
        try {
            check_writable_image_path((fs::path(report_files_dir(page.output)) / "probe.png").string());
        } catch (const ImageIoError& e) {
            throw UsageError(fmt::format("-o {}: {}", page.output, e.what()));
        }
        pages.push_back(std::move(page));
    }

    // The given references: read, and refused when of another size, or (by their manifest) of
    // another scene or estimator family.
    // The insets and the guide's pixel inside a w x h image.
    const auto check_inside = [&](int w, int h) {
        if (guide_pixel && (guide_pixel->first >= w || guide_pixel->second >= h))
            throw UsageError(fmt::format("--guide-pixel {},{} is not inside the {}x{} image", guide_pixel->first, guide_pixel->second, w, h));
        for (const PixelRect& c : crops)
            if (c.x + c.width > w || c.y + c.height > h)
                throw UsageError(fmt::format("--crop {},{},{},{} is not inside the {}x{} image", c.x, c.y, c.width, c.height, w, h));
    };
    std::vector<ReportData> datas(pages.size());
    for (size_t i = 0; i < pages.size(); ++i) {
        const PageJob& page = pages[i];
        ReportData& data = datas[i];
        JobRequest sized;  // the size of a render of --resolution (else of the scene's own)
        sized.width = width, sized.height = height;
        const RenderJob sized_job(page.choice, sized);
        if (page.reference.empty()) {
            check_inside(sized_job.width(), sized_job.height());
            continue;
        }
        try {
            data.reference = read_image(page.reference);
            if (fs::exists(stderr_path_for(page.reference))) data.reference_se = read_image(stderr_path_for(page.reference));
        } catch (const ImageIoError& e) {
            throw UsageError(e.what());
        }
        const int w = width > 0 ? sized_job.width() : data.reference.width(), h = width > 0 ? sized_job.height() : data.reference.height();
        if (w != data.reference.width() || h != data.reference.height())
            throw UsageError(fmt::format("--resolution {}x{} differs from the reference {} ({}x{})", w, h, page.reference,
                                         data.reference.width(), data.reference.height()));
        if (const std::optional<ReferenceRecord> record = find_reference_record(page.reference)) {
            for (const IntegratorInfo* e : infos) {
                JobRequest request;
                request.algorithm = e->name;
                request.max_depth = o.max_depth;
                const RenderJob job(page.choice, request);
                const std::string why = reference_mismatch(*record, page.reference, page.choice, job.family(), w, h);
                if (!why.empty()) throw UsageError(fmt::format("report {}: {}", e->name, why));
            }
        }
        if (data.reference_se.pixel_count() && data.reference_se.pixel_count() != data.reference.pixel_count()) data.reference_se = Image();
        data.reference_label = fs::path(page.reference).filename().string();
        data.reference_note = fmt::format("{} (given){}", page.reference, data.reference_se.pixel_count() ? ", with its standard errors" : "");
        check_inside(w, h);
    }

    std::optional<tbb::global_control> thread_limit;
    limit_threads(thread_limit, o.threads);
    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);
    const std::string budget = o.time_limit > 0 ? fmt::format("equal time: {} s per algorithm", o.time_limit)
                                                : fmt::format("equal samples: {} spp per algorithm", o.spp);

    InterruptGuard interrupt;
    bool interrupted = false;
    for (size_t i = 0; i < pages.size() && !interrupted; ++i) {
        const PageJob& page = pages[i];
        const SceneChoice& choice = page.choice;
        ReportData& data = datas[i];
        data.title = choice.builtin ? fmt::format("scene {} {}", *choice.builtin, choice.name) : fmt::format("{} ({})", choice.name, choice.file);
        data.budget = budget;
        data.crops = crops;
        if (pages.size() > 1 && !o.quiet) fmt::print(stderr, "report of {} -> {}\n", choice.name, page.output);

        if (data.reference.pixel_count() == 0) {
            JobRequest ref_request;
            ref_request.algorithm = reference_algorithm;
            ref_request.max_depth = all_direct ? std::optional<int>(1) : o.max_depth;
            ref_request.width = width;
            ref_request.height = height;
            ref_request.spp = uint64_t(o.reference_spp);
            ref_request.seed = seed + 1000003;  // independent of the compared renders
            RenderJob ref_job(choice, ref_request);
            const std::string saved = (fs::path(report_files_dir(page.output)) / "reference.exr").string();
            const uint64_t ref_spp = ref_job.settings.spp;
            ref_job.settings.progress = show_progress;
            ref_job.settings.cancel = &InterruptGuard::flag();
            // Say what the reference costs before it takes its time: after its first passes, how
            // long all of them will take, and how to give one instead.
            bool said = false;
            if (!o.quiet) {
                fmt::print(stderr, "reference: none given, so it is rendered first with {}{} at {} spp (to use one: --reference FILE; "
                                   "this one will be saved as {}; fewer samples: --reference-spp N)\n",
                           reference_algorithm, all_direct ? " --max-depth 1" : "", ref_spp, saved);
                ref_job.settings.after_pass = [&, ref_spp](const Film&, const RenderStats& st) {
                    if (said || st.spp == 0 || st.spp >= ref_spp) return;
                    said = true;
                    const double total = st.seconds / double(st.spp) * double(ref_spp);
                    const double rest = o.time_limit > 0 ? o.time_limit * double(infos.size()) : 0;
                    fmt::print(stderr, "reference: about {:.0f} s (from its first {} spp){}\n", std::ceil(total), st.spp,
                               rest > 0 ? fmt::format(", then {} x {} s for the algorithms", infos.size(), o.time_limit) : "");
                };
            }
            const RenderResult r = ref_job.run();
            data.reference = r.film.mean();
            data.reference_se = r.film.standard_error();
            write_image(data.reference, saved);
            write_image(data.reference_se, stderr_path_for(saved));
            ReferenceRecord record;
            record.file = "reference.exr";
            record.scene = choice.name;
            record.index = choice.builtin;
            record.scene_file = choice.file;
            record.scene_hash = choice.hash;
            record.parameters = choice.parameters;
            record.stderr_file = fs::path(stderr_path_for(saved)).filename().string();
            record.algorithm = reference_algorithm;
            record.family = ref_job.family();
            record.max_depth = ref_job.integrator_options().max_depth;
            record.width = r.film.width();
            record.height = r.film.height();
            record.spp = r.stats.spp;
            record.seed = ref_request.seed;
            record.seconds = r.stats.seconds;
            record.invalid_samples = r.stats.invalid_samples;
            record.interrupted = r.stats.interrupted;
            record_reference(report_files_dir(page.output), record);
            data.reference_note = fmt::format("none given, so rendered here with {}{} at {} spp in {:.1f} s (saved as {}; reuse it with --reference)",
                                              reference_algorithm, all_direct ? " --max-depth 1 (direct illumination)" : "",
                                              r.stats.spp, r.stats.seconds, saved);
            data.reference_label = fmt::format("{}{}, {} spp", reference_algorithm, all_direct ? " (direct)" : "", r.stats.spp);
            if (r.stats.interrupted) {
                interrupted = true;
                data.notes.push_back(fmt::format("Interrupted while rendering the reference (after {} spp): no algorithm was rendered.", r.stats.spp));
            }
        }
        data.command = command_line(o, choice.file.empty() ? choice.name : choice.file, page.output, page.reference);

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
            ReportRender entry;
            entry.algorithm = e->name;
            double next_checkpoint = 0;
            RenderSettings& rs = job.settings;
            rs.progress = show_progress;
            rs.cancel = &InterruptGuard::flag();
            rs.after_pass = [&](const Film& film, const RenderStats& st) {
                const bool last = (rs.spp > 0 && st.spp >= rs.spp) || (rs.time_limit > 0 && st.seconds >= rs.time_limit);
                if (st.seconds < next_checkpoint && !last) return;
                entry.convergence.push_back({st.seconds, st.spp, rmse_against_reference(film.mean(), data.reference, data.reference_se)});
                next_checkpoint = st.seconds * kCheckpointGrowth;
            };
            if (!o.quiet) fmt::print(stderr, "{}\n", e->name);
            const RenderResult r = job.run();
            entry.mean = r.film.mean();
            entry.std_error = r.film.standard_error();
            entry.stats = r.stats;
            if (guide_pixel)
                if (const SdTree* tree = trained_guide(job.integrator())) {
                    const PerspectiveCamera camera(job.scene().camera(), entry.mean.width(), entry.mean.height());
                    Intersection hit;
                    const float x = float(guide_pixel->first) + 0.5f, y = float(guide_pixel->second) + 0.5f;
                    if (job.scene().intersect(camera.generate(x, y), hit)) {
                        entry.guide_map = guide_map(*tree, hit.p);
                        entry.guide_note = fmt::format("pixel ({}, {}): first hit at ({:.3g}, {:.3g}, {:.3g})", guide_pixel->first,
                                                       guide_pixel->second, hit.p.x, hit.p.y, hit.p.z);
                        // Where the leaf guides: how much of the mixture is the BSDF's (--guiding-fraction).
                        const GuidingLeaf& leaf = tree->leaf(hit.p);
                        const IntegratorOptions& options = job.integrator_options();
                        if (leaf.usable)
                            entry.guide_note += fmt::format("; BSDF sampling fraction there {:.3g} ({})", guiding_bsdf_fraction(options, leaf),
                                                            options.guiding_fraction == kLearnedGuidingFraction ? "learned" : "--guiding-fraction");
                        if (options.guiding == GuidingModel::kVmm) entry.guide_note += "; von Mises-Fisher mixture (--guiding vmm)";
                    } else {
                        entry.guide_note = fmt::format("pixel ({}, {}): its ray leaves the scene", guide_pixel->first, guide_pixel->second);
                    }
                }
            // The final point, if the last pass did not make a checkpoint (the time budget ended it).
            if (entry.convergence.empty() || entry.convergence.back().spp < r.stats.spp)
                entry.convergence.push_back({r.stats.seconds, r.stats.spp, rmse_against_reference(entry.mean, data.reference, data.reference_se)});
            if (!o.quiet)
                fmt::print(stderr, "  {} spp in {:.2f} s, RMSE {:.4g}\n", r.stats.spp, r.stats.seconds, entry.convergence.back().rmse);
            if (r.stats.interrupted) {
                interrupted = true;
                data.notes.push_back(fmt::format("Interrupted: {} stopped after {} spp ({:.2f} s), so it is not an equal-{} comparison.",
                                                 e->name, r.stats.spp, r.stats.seconds, o.time_limit > 0 ? "time" : "sample"));
            }
            data.renders.push_back(std::move(entry));
        }

        const std::vector<std::string> files = write_html_report(data, page.output);
        if (!o.quiet) fmt::print(stderr, "{} ({} files in {})\n", page.output, files.size() - 1, report_files_dir(page.output));
    }
    return interrupted ? interrupted_exit_code() : 0;
}

}  // namespace pathlab
