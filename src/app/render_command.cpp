#include "app/render_command.hpp"

#include <tbb/global_control.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "app/command_arguments.hpp"
#include "app/interrupt.hpp"
#include "display/display_server.hpp"
#include "display/tev_protocol.hpp"
#include "job/usage_error.hpp"
#include "image/image_io.hpp"
#include "job/extra_channels.hpp"
#include "integrators/bidir/strategy_images.hpp"
#include "integrators/common/path_rules.hpp"
#include "job/output_paths.hpp"
#include "job/checkpoint.hpp"
#include "job/job_checkpoint.hpp"
#include "job/rank_group.hpp"
#include "job/render_identity.hpp"
#include "job/render_job.hpp"


namespace pathlab {
namespace {

constexpr int kDefaultSpp = 64;
const char* const kDefaultOutputs[] = {"out/{index}-{scene}-{algorithm}.exr", "out/{index}-{scene}-{algorithm}.png"};

void write_stats(const std::string& path, RenderJob& job, const RenderResult& r, int threads, int rank_count) {
    const RenderStats& s = r.stats;
    const RenderSettings& rs = job.settings;
    nlohmann::json j = {
        {"pathlab_version", PATHLAB_VERSION},
        {"scene", job.scene_choice().name},
        {"algorithm", job.integrator_info().name},
        {"resolution", {r.film.width(), r.film.height()}},
        {"spp", s.spp},
        {"seed", rs.seed},
        {"sampler", rs.sampler == SamplerKind::Sobol ? "sobol" : "independent"},
        {"mode", rs.spectral ? "spectral" : "rgb"},
        {"threads", threads},
        {"processes", rank_count},
        {"first_sample", s.passes.begin()},
        {"passes", s.passes.to_string()},
        {"resumed_spp", s.resumed_spp},
        {"reduce_seconds", s.reduce_seconds},
        {"checkpoints", s.checkpoints},
        {"checkpoint_seconds", s.checkpoint_seconds},
        {"seconds", s.seconds},
        {"samples", s.samples},
        {"samples_per_second", s.seconds > 0 ? double(s.samples) / s.seconds : 0.0},
        {"rays", s.rays},
        {"rays_per_second", s.seconds > 0 ? double(s.rays) / s.seconds : 0.0},
        {"invalid_samples", s.invalid_samples},
        {"interrupted", s.interrupted},
        {"outputs", job.outputs},
    };
    for (const IntegratorStatistic& x : s.integrator) j["integrator"][x.name] = x.value;
    for (const RankStats& k : s.ranks)
        j["ranks"].push_back({{"name", k.name},
                              {"spp", k.spp},
                              {"seconds", k.seconds},
                              {"samples_per_second", k.seconds > 0 ? double(k.spp) * double(r.film.pixel_count()) / k.seconds : 0.0},
                              {"rays", k.rays}});
    write_text_file(path, j.dump(2) + "\n");
}

}  // namespace

void add_render_options(CLI::App& app, RenderCommandOptions& o) {
    add_scene_arguments(app, o.scenes);
    app.add_option_function<std::string>(
        "-a,--algorithm", [&o](const std::string& v) { o.algorithm = v, o.algorithm_given = true; },
        "Estimator name or course alias (see `pathlab algorithms`), a comma-separated list, or all; default: the scene file's "
        "integrator, else pt-mis");
    app.add_option_function<int>("--spp", [&o](const int& v) { o.spp = v, o.spp_given = true; },
                                 fmt::format("Samples per pixel (default {}, or unlimited with --time)", kDefaultSpp));
    app.add_option("--time", o.time_limit, "Time budget in seconds per scene (stops at --spp if that comes first)");
    app.add_option("--resolution", o.resolution, "Image size WxH (default: the scene's, 512x512 for the course)");
    app.add_option("--seed", o.seed, "Random seed, 0 to 18446744073709551615; the image is a pure function of it")
        ->capture_default_str();
    app.add_option("--sampler", o.sampler,
                   "Random numbers: 'independent' (PCG32; the course's setting, exact per-pixel standard errors) or "
                   "'sobol' (scrambled low-discrepancy points: lower error at equal time)")
        ->capture_default_str();
    app.add_flag("--spectral", o.spectral,
                 "Spectral mode: paths carry 4 sampled wavelengths, RGB inputs are upsampled (docs/spectral.md); every "
                 "algorithm renders in it. Also a scene file's <default name=\"mode\" value=\"spectral\"/>");
    add_threads_option(app, o.threads);
    app.add_option("-o,--output", o.outputs,
                   "Output file, repeatable; format by extension: .exr .hdr .pfm .png. Placeholders {scene} {dir} (the scene file's "
                   "folder) {path} (its path, folders joined by '-') {index} {algorithm}. Default: out/{index}-{scene}-{algorithm}.exr "
                   "and .png ({dir}-{scene}, else {path}, where scene files of one name in different folders would collide)");
    app.add_option("--exposure", o.exposure, "Exposure in stops for .png output")->capture_default_str();
    app.add_option("--stats", o.stats_path, "Write render statistics as JSON (placeholders as for -o)");
    app.add_option_function<int>("--max-depth", [&o](const int& v) { o.max_depth = v, o.max_depth_given = true; },
                                 "Longest path in bounces (-1: unlimited; default: the scene file's, else -1)");
    app.add_option_function<int>("--rr-depth", [&o](const int& v) { o.rr_depth = v, o.rr_depth_given = true; },
                                 "Bounces before Russian roulette starts (default: the scene file's, else 3)");
    app.add_option("--null-depth", o.null_depth,
                   "Whether a straight pass through a surface (thindielectric's transmission, a mask's hole) counts toward "
                   "--max-depth: count (a bounce, as Mitsuba's path) or skip (no bounce, as Mitsuba's volpath; pt-mis, pt-mis3, "
                   "volpath, pssmlt). Default: the scene file's (skip for <integrator type=\"volpath\">), else count");
    app.add_option("--light-sampler", o.light_sampler,
                   "How next-event estimation chooses a light: uniform (every emitter alike, a mesh's triangles by area), power (default: in proportion to power), bvh (a "
                   "light tree, by each light's bound at the shading point: for many lights) or ris (bvh's choices as "
                   "candidates, one kept by its unshadowed contribution); for the integrators that sample lights at their "
                   "shading points (pathlab algorithms)");
    app.add_option("--ris-candidates", o.ris_candidates,
                   fmt::format("--light-sampler ris: the light samples drawn to keep one (1 to {}; default {})", kMaxRisCandidates,
                               kDefaultRisCandidates));
    app.add_option("--light-split", o.light_split,
                   fmt::format("--light-sampler bvh: adaptive splitting (Conty Estevez and Kulla 2018): where the light tree's root's "
                               "bounding sphere's radius over its distance to the shading point exceeds this, next-event estimation "
                               "takes a light sample from each of the root's children instead of choosing one (the path tracers: at "
                               "their first vertex; 0: never; up to {}; default {})",
                               kMaxLightSplit, kDefaultLightSplit));
    app.add_option("--mis", o.mis, "bdpt, vcm, bpm, upbp, mmlt, pt-mis, pt-mis3, direct-mis, volpath: the MIS heuristic, balance or power (Mitsuba's path tracers')")->capture_default_str();
    app.add_option("--strategies", o.strategies_dir,
                   "bdpt: also write one image per strategy (s, t), weighted and unweighted, and montages, into this directory "
                   "(placeholders as for -o)");
    app.add_option("--strategies-depth", o.strategies_depth, "bdpt: ... for paths of up to this many bounces")->capture_default_str();
    app.add_option("--photons", o.photons, "sppm, ppm: light paths per iteration (default one per pixel); pm: light paths of its maps (8 per pixel)");
    app.add_option("--radius", o.photon_radius,
                   "sppm, ppm, vcm, bpm: the first iteration's photon radius (default two pixel footprints at the scene's centre); pm: a fixed "
                   "radius instead of the k nearest");
    app.add_option("--alpha", o.photon_alpha, "sppm, ppm, vcm, bpm: the radius reduction, in (0, 1] (default 2/3)");
    app.add_option("--volume-estimate", o.volume_estimate,
                   "sppm, ppm, pm in media: beam (the beam radiance estimate along the camera rays, default) or points (the 3D "
                   "kernel at the camera path's scattering points)");
    app.add_flag("--no-merging", o.no_merging, "vcm: connections only (then it is bdpt)");
    app.add_flag("--no-connections", o.no_connections, "vcm: merging only (then it is bpm)");
    app.add_option("--ic-rays", o.ic_rays, "ic: rays per irradiance record (stratified; default 256)");
    app.add_option("--ic-error", o.ic_error, "ic: the error threshold a (0: no cache, every point gathers for itself; default 0.2)");
    app.add_flag("--ic-no-gradients", o.ic_no_gradients, "ic: interpolate without the irradiance gradients");
    app.add_option("--ic-records", o.ic_records, "ic: write an image of the cached light with the records as red dots (placeholders as for -o)");
    app.add_option("--pbgi-surfels", o.pbgi_surfels, "pbgi: about this many surfels over the scene's surfaces (default 8000)");
    app.add_option("--pbgi-cutoff", o.pbgi_cutoff,
                   "pbgi: the solid angle (sr) above which a cluster is opened (default 0.05; 0: every surfel, brute force)");
    app.add_option("--pbgi-bounces", o.pbgi_bounces, "pbgi: surfel bounces (1: the surfels' direct light only; default 3)");
    app.add_option("--pbgi-resolution", o.pbgi_resolution, "pbgi: the micro-buffer's side in pixels (default 16)");
    app.add_option("--pbgi-direct-samples", o.pbgi_direct_samples, "pbgi: MIS pairs for each surfel side's direct light (default 16)");
    app.add_option("--pbgi-spacing", o.pbgi_spacing, "pbgi: pixels between the gathers at the first hits, interpolated between (default 2)");
    app.add_option("--guiding-spp", o.guiding_spp,
                   "ppg: samples per pixel of the SD-tree's training, in iterations of 1, 2, 4, ... spp before the image's samples and "
                   "not in the image (default 31; 0: no guiding)");
    app.add_flag("--guiding-rr", o.guiding_rr,
                 "ppg: adjoint-driven Russian roulette and splitting (Vorba and Krivanek 2016): paths whose expected contribution, "
                 "learned with the SD-tree, is small against the pixel's are ended, large ones split (default: the throughput's roulette)");
    app.add_option("--guiding-fraction", o.guiding_fraction,
                   "ppg: the probability of sampling the BSDF rather than the SD-tree where it guides: a number in (0, 1] (default 0.5, "
                   "the paper's) or 'learned' (per spatial leaf during training, by Adam on the KL divergence's gradient; Mueller 2019)");
    app.add_option("--guiding", o.guiding,
                   "ppg: what each spatial leaf learns of the arriving light: sd-tree (a quadtree over directions, Mueller et al. 2017; "
                   "the default) or vmm (a mixture of von Mises-Fisher lobes fitted by on-line EM, Vorba et al. 2014)");
    app.add_option("--estimators", o.estimators,
                   "upbp: the estimators it combines by MIS, comma-separated, of bpt (bdpt's connections), surf (photon merging on "
                   "surfaces), pp3d (photon points merged at points in media), pb2d (photon points gathered along the camera rays in "
                   "media), bb1d (photon beams against the camera rays in media); SmallUPBP's names (default: all)");
    app.add_option("--beam-radius", o.beam_radius,
                   "upbp: the first radius of its beam estimators (pb2d, bb1d), in scene units, reduced as --radius is (default: a "
                   "quarter of --radius's)");
    app.add_option("--photon-beams", o.photon_beams,
                   "upbp: light paths per iteration whose edges in media are kept as photon beams for bb1d (the first K of the "
                   "iteration's one per pixel; default 256, or the pixel count if fewer)");
    app.add_option("--chains", o.mlt_chains,
                   "pssmlt, mmlt: Markov chains per pass (a fixed number, so the image does not depend on the threads; default 64)");
    app.add_option("--bootstrap", o.mlt_bootstrap,
                   "pssmlt, mmlt: independent paths of each pass's bootstrap, which estimates the normalisation b and starts the chains "
                   "(default 4096)");
    app.add_option("--large-step", o.mlt_large_step, "pssmlt, mmlt: the probability of a large step (every number fresh; default 0.3)");
    app.add_option("--sigma", o.mlt_sigma, "pssmlt, mmlt: the small steps' standard deviation in primary sample space (default 0.01)");
    app.add_option("--checkpoint", o.checkpoint,
                   "Save the render's whole state to this file (atomically) every --checkpoint-every seconds, at the end and "
                   "when interrupted, to continue it with --resume (placeholders as for -o)");
    app.add_option("--checkpoint-every", o.checkpoint_every, "Seconds between checkpoints (0: only at the end and when interrupted)")
        ->capture_default_str();
    app.add_option("--resume", o.resume,
                   "Continue the render saved in this checkpoint (same scene and settings; --spp may be raised); it goes on "
                   "checkpointing to the same file unless --checkpoint says otherwise");
    app.add_option("--first-sample", o.first_sample,
                   "Index of the first sample (pass) to render: renders of disjoint ranges add up, with `pathlab merge`, to one render")
        ->capture_default_str();
    app.add_option("--aovs", o.aovs,
                   "Auxiliary images as layers of the EXR output, from the render's own samples: albedo, normal, depth, position "
                   "(at each sample's first non-specular vertex, through mirrors and glass; pixel integrators), variance, "
                   "sample-count (every integrator); comma-separated");
    app.add_option("--display-server", o.display_server,
                   fmt::format("Show the render as it converges in a running tev (its HOST:PORT; port {} when only HOST is "
                               "given): the image is sent after the first pass and then twice a second. An unreachable viewer "
                               "never stops the render (pathlab says so once and tries again in the background)",
                               tev::kDefaultPort));
    app.add_flag("-q,--quiet", o.quiet, "No progress line and no summary");
}

namespace {

// The jobs of a render command (one per scene and algorithm), validated (UsageError on bad
// usage); `check_paths`: the outputs are checked for writability (by the rank that writes them).
std::vector<RenderJob> make_jobs(const RenderCommandOptions& o, bool check_paths, std::vector<std::string>& checkpoints,
                                 std::vector<std::string>& resumes, bool distributed) {
    std::vector<const IntegratorInfo*> algorithms;
    if (o.algorithm_given) algorithms = parse_algorithm_list(o.algorithm);
    JobRequest request;
    if (o.spp_given) {
        if (o.spp <= 0) throw UsageError(fmt::format("--spp must be a positive number of samples, got {}", o.spp));
        request.spp = uint64_t(o.spp);
    }
    if (o.max_depth_given) request.max_depth = o.max_depth;
    if (o.rr_depth_given) {
        if (o.rr_depth < 0) throw UsageError("--rr-depth must be zero or positive");
        request.rr_depth = o.rr_depth;
    }
    parse_resolution_option(o.resolution, request.width, request.height);
    request.time_limit = o.time_limit;
    request.seed = parse_seed_option(o.seed);
    if (o.sampler != "independent" && o.sampler != "sobol")
        throw UsageError(fmt::format("unknown sampler '{}'. Valid samplers: independent, sobol", o.sampler));
    request.sampler = o.sampler == "sobol" ? SamplerKind::Sobol : SamplerKind::Independent;
    request.default_spp = kDefaultSpp;
    request.spectral = o.spectral;
    if (o.mis != "balance" && o.mis != "power")
        throw UsageError(fmt::format("unknown MIS heuristic '{}'. Valid heuristics: balance, power", o.mis));
    request.mis_power = o.mis == "power";
    if (o.light_sampler) {
        request.light_sampler = parse_light_sampler(*o.light_sampler);
        if (!request.light_sampler)
            throw UsageError(fmt::format("unknown light sampler '{}'. Valid light samplers: {}", *o.light_sampler, kLightSamplerNames));
    }
    request.ris_candidates = o.ris_candidates;
    request.light_split = o.light_split;
    if (o.null_depth) {
        if (*o.null_depth != "count" && *o.null_depth != "skip")
            throw UsageError(fmt::format("unknown --null-depth '{}'. Valid: count, skip", *o.null_depth));
        request.skip_null_events = *o.null_depth == "skip";
    }
    request.strategies_depth = o.strategies_depth;
    request.photons = o.photons;
    request.photon_radius = o.photon_radius;
    request.photon_alpha = o.photon_alpha;
    if (o.volume_estimate) {
        if (*o.volume_estimate != "beam" && *o.volume_estimate != "points")
            throw UsageError(fmt::format("unknown volume estimate '{}'. Valid estimates: beam, points", *o.volume_estimate));
        request.volume_beam = *o.volume_estimate == "beam";
    }
    request.vcm_merging = !o.no_merging;
    request.vcm_connections = !o.no_connections;
    request.ic_rays = o.ic_rays;
    request.ic_error = o.ic_error;
    if (o.ic_no_gradients) request.ic_gradients = false;
    request.ic_records = !o.ic_records.empty();
    request.pbgi_surfels = o.pbgi_surfels;
    request.pbgi_cutoff = o.pbgi_cutoff;
    request.pbgi_bounces = o.pbgi_bounces;
    request.pbgi_resolution = o.pbgi_resolution;
    request.pbgi_direct_samples = o.pbgi_direct_samples;
    request.pbgi_spacing = o.pbgi_spacing;
    request.guiding_spp = o.guiding_spp;
    request.guiding_rr = o.guiding_rr;
    if (!o.guiding_fraction.empty()) request.guiding_fraction = o.guiding_fraction;
    if (!o.guiding.empty()) request.guiding = o.guiding;
    request.estimators = o.estimators;
    request.photon_beams = o.photon_beams;
    request.beam_radius = o.beam_radius;
    request.first_sample = o.first_sample;
    request.mlt_chains = o.mlt_chains;
    request.mlt_bootstrap = o.mlt_bootstrap;
    request.mlt_large_step = o.mlt_large_step;
    request.mlt_sigma = o.mlt_sigma;
    request.checkpoint_every = o.checkpoint_every;
    if (!o.aovs.empty()) {
        request.aovs = split_comma_list(o.aovs);
        // The AOV sums are neither in checkpoints nor reduced across processes.
        if (!o.checkpoint.empty() || !o.resume.empty()) throw UsageError("--aovs cannot be checkpointed yet: render it without --checkpoint and --resume");
        if (distributed) throw UsageError("--aovs are recorded in one process: render them without mpirun");
        if (o.first_sample != 0) throw UsageError("--aovs with --first-sample: the AOVs of parts cannot be merged yet; render them in one go");
        const bool exr = std::any_of(o.outputs.begin(), o.outputs.end(), [](const std::string& p) { return image_format_for(p) == ImageFormat::Exr; });
        if (!o.outputs.empty() && !exr) throw UsageError("--aovs are written as layers of an EXR: give an -o ending in .exr");
    }
    if (!o.display_server.empty() && !parse_display_address(o.display_server))
        throw UsageError(fmt::format("--display-server: '{}' is not HOST, HOST:PORT or [IPv6]:PORT (a port from 1 to 65535)",
                                     o.display_server));

    std::vector<RenderJob> jobs;
    // -a all: every estimator that renders the scene; those that cannot (a medium, spectral mode,
    // the sensor) are left out, with a note saying which and why.
    const bool every = o.algorithm_given && o.algorithm == "all";
    for (SceneChoice& choice : resolve_scene_arguments(o.scenes)) {
        if (algorithms.empty()) {
            jobs.emplace_back(std::move(choice), request);
            continue;
        }
        std::vector<std::string> left_out, reasons;
        for (const IntegratorInfo* info : algorithms) {
            request.algorithm = info->name;
            if (every)
                if (const std::string why = integrator_refusal(*info, choice.description, request); !why.empty()) {
                    left_out.push_back(info->name), reasons.push_back(why);
                    continue;
                }
            jobs.emplace_back(choice, request);
        }
        if (left_out.size() == algorithms.size()) throw UsageError(fmt::format("-a all: no estimator renders {}: {}", choice.name, reasons[0]));
        if (!left_out.empty() && !o.quiet)
            fmt::print(stderr, "pathlab: note: -a all on {}: {} left out, as they cannot render it (e.g. {})\n", choice.name,
                       fmt::join(left_out, ", "), reasons[0]);
    }
    std::vector<std::string> patterns(o.outputs.begin(), o.outputs.end());
    if (patterns.empty()) {
        patterns.assign(std::begin(kDefaultOutputs), std::end(kDefaultOutputs));
        // Scene files of one name in different folders (DIR/scene.xml): the folder goes into the
        // default names, or where folders of one name differ too (a/k/scene.xml, b/k/scene.xml), the path.
        const auto collide = [&](const char* key) {
            for (size_t j = 0; j < jobs.size(); ++j)
                for (size_t k = 0; k < j; ++k)
                    if (jobs[j].scene_choice().file != jobs[k].scene_choice().file && jobs[j].expand(key) == jobs[k].expand(key)) return true;
            return false;
        };
        if (collide("{scene}")) {
            const char* names = collide("{dir}-{scene}") ? "{path}" : "{dir}-{scene}";
            for (std::string& p : patterns) p.replace(p.find("{scene}"), 7, names);
        }
    }
    // Check every output before the first render starts: writable, not an input, not another output.
    OutputPaths paths;
    for (const RenderJob& job : jobs)
        paths.scene_inputs(job.scene_choice());
    for (RenderJob& job : jobs) {
        const std::string checkpoint = o.checkpoint.empty() ? "" : job.expand(o.checkpoint);
        resumes.push_back(o.resume.empty() ? "" : job.expand(o.resume));
        checkpoints.push_back(checkpoint_file(checkpoint, resumes.back()));
        add_resume_input(paths, checkpoint, resumes.back());
    }
    for (size_t j = 0; j < jobs.size(); ++j) {
        // Notes of the scene loader: what it accepted and ignored, or changed.
        if (!o.quiet)
            for (const std::string& note : jobs[j].scene_choice().description.notes) fmt::print(stderr, "{}\n", note);
        // Without -o, the scene file's hdrfilm file_format chooses the HDR output's format.
        const std::string& format = jobs[j].scene_choice().description.file_format;
        for (std::string p : patterns) {
            if (o.outputs.empty() && p.ends_with(".exr") && format != "openexr" && o.aovs.empty())  // (the AOVs need the EXR)
                p = p.substr(0, p.size() - 4) + (format == "rgbe" ? ".hdr" : ".pfm");
            jobs[j].outputs.push_back(jobs[j].expand(p));
        }
        for (size_t k = 0; k < j; ++k)
            for (const std::string& path : jobs[j].outputs)
                if (std::find(jobs[k].outputs.begin(), jobs[k].outputs.end(), path) != jobs[k].outputs.end())
                    throw UsageError(fmt::format("{} / {} and {} / {} would both write {}: add {{scene}}, {{dir}}, {{path}}, {{index}} or {{algorithm}} to -o",
                                                 jobs[k].scene_choice().name, jobs[k].integrator_info().name,
                                                 jobs[j].scene_choice().name, jobs[j].integrator_info().name, path));
        if (check_paths) {
            for (const std::string& path : jobs[j].outputs) paths.output(path, "the output", /*image=*/true);
            if (!o.stats_path.empty()) paths.output(jobs[j].expand(o.stats_path), "--stats", /*image=*/false);
            if (!checkpoints[j].empty()) {
                for (size_t k = 0; k < j; ++k)
                    if (checkpoints[k] == checkpoints[j])
                        throw UsageError(fmt::format("{} / {} and {} / {} would both checkpoint to {}: add {{scene}}, {{index}} or "
                                                     "{{algorithm}} to it",
                                                     jobs[k].scene_choice().name, jobs[k].integrator_info().name,
                                                     jobs[j].scene_choice().name, jobs[j].integrator_info().name, checkpoints[j]));
                add_checkpoint_output(paths, checkpoints[j], resumes[j]);
            }
        }
        // (The options of other estimators, --ic-records too, are refused by RenderJob.)
        if (!o.ic_records.empty()) {
            const std::string p = jobs[j].expand(o.ic_records);
            paths.output(p, "--ic-records", /*image=*/true);
            jobs[j].integrator_options().ic_records_path = p;
        }
        if (!o.strategies_dir.empty()) {
            if (jobs[j].integrator_info().name != "bdpt")
                throw UsageError(fmt::format("--strategies writes the strategies of bdpt, not of {}", jobs[j].integrator_info().name));
            // The depth bdpt writes is the lower of --strategies-depth and the paths' own limit.
            const IntegratorOptions& io = jobs[j].integrator_options();
            const bool unlimited = io.max_depth < 0;
            const int depth = std::min(io.strategies_depth, bounce_limit(io.max_depth)), most = StrategyImages::kMaxLength;
            if (depth > most)
                throw UsageError(fmt::format(
                    "--strategies images of paths up to {} bounces would be {} strategies and {} files; at most {} bounces are written "
                    "({} strategies): lower --strategies-depth{}",
                    depth, StrategyImages::count(depth), 4 * StrategyImages::count(depth), most, StrategyImages::count(most),
                    unlimited ? " or give --max-depth (paths are unlimited here)" : " or --max-depth"));
            const std::string dir = jobs[j].expand(o.strategies_dir);
            paths.output((std::filesystem::path(dir) / "montage-weighted.png").string(), "--strategies", /*image=*/true);
            jobs[j].integrator_options().strategies_dir = dir;
            if (distributed || !checkpoints[j].empty())
                throw UsageError("--strategies keeps per-strategy images that checkpoints and processes do not carry; render them in "
                                 "one process without --checkpoint and --resume");
        }
    }
    return jobs;
}

// Messages agreed on by the ranks (RankGroup::agree), each line as pathlab prints errors.
void print_messages(const std::string& messages) {
    for (size_t a = 0; a < messages.size();) {
        size_t b = messages.find('\n', a);
        if (b == std::string::npos) b = messages.size();
        // A message's continuation lines (indented) are printed as they are; a message that
        // ends its last line leaves no empty one.
        if (b > a) fmt::print(stderr, "{}{}\n", messages[a] == ' ' ? "" : "pathlab: ", messages.substr(a, b - a));
        a = b + 1;
    }
}

void print_summary(const RenderJob& job, const std::string& name, const RenderStats& s) {
    fmt::print(stderr, "{}{}: {} spp{} in {:.2f}s ({:.2f} Msamples/s, {:.2f} Mrays/s){}{} -> {}\n", name,
               job.settings.spectral ? " (spectral)" : "", s.spp,
               s.resumed_spp ? fmt::format(" ({} resumed)", s.resumed_spp) : "", s.seconds,
               s.seconds > 0 ? double(s.samples) / s.seconds * 1e-6 : 0.0, s.seconds > 0 ? double(s.rays) / s.seconds * 1e-6 : 0.0,
               s.invalid_samples ? fmt::format(", {} NaN/Inf samples discarded", s.invalid_samples) : "",
               s.integrator.empty() ? "" : fmt::format(", {}", fmt::join([&] {
                   std::vector<std::string> parts;
                   for (const IntegratorStatistic& x : s.integrator) parts.push_back(fmt::format("{} {:g}", x.name, x.value));
                   return parts;
               }(), ", ")),
               fmt::join(job.outputs, ", "));
    if (s.ranks.size() > 1) {
        const double pixels = double(s.samples) / double(std::max<uint64_t>(1, s.spp - s.resumed_spp));
        for (const RankStats& k : s.ranks)
            fmt::print(stderr, "  {}: {} spp in {:.2f}s ({:.2f} Msamples/s)\n", k.name, k.spp, k.seconds,
                       k.seconds > 0 ? double(k.spp) * pixels / k.seconds * 1e-6 : 0.0);
        fmt::print(stderr, "  film reduction {:.3f}s\n", s.reduce_seconds);
    }
    if (s.checkpoints) fmt::print(stderr, "  {} checkpoint(s) written in {:.3f}s\n", s.checkpoints, s.checkpoint_seconds);
    if (s.failed_checkpoints) fmt::print(stderr, "  {} checkpoint(s) could not be written\n", s.failed_checkpoints);
}

}  // namespace

int run_render_command(const RenderCommandOptions& o, RankGroup* ranks) {
    LocalRanks alone;
    RankGroup& group = ranks ? *ranks : alone;
    const bool root = group.root(), distributed = group.size() > 1;
    // Everything that may fail before the renders, agreed on by the ranks (a rank that stopped
    // alone would leave the others waiting).
    std::vector<RenderJob> jobs;
    std::vector<std::string> checkpoints, resumes;
    {
        int code = 0;
        std::string message;
        try {
            jobs = make_jobs(o, root, checkpoints, resumes, distributed);
        } catch (const UsageError& e) {
            if (!distributed) throw;
            code = 2, message = e.what();
        } catch (const std::exception& e) {
            if (!distributed) throw;
            code = 1, message = fmt::format("error: {}", e.what());
        }
        std::string messages;
        if (const int agreed = group.agree(code, message, &messages)) {
            if (root) print_messages(messages);
            return agreed;
        }
    }
    const bool several_algorithms = o.algorithm_given && parse_algorithm_list(o.algorithm).size() > 1;

    std::optional<tbb::global_control> thread_limit;
    limit_threads(thread_limit, o.threads);
    const int threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

    const bool show_progress = root && !o.quiet && isatty(STDERR_FILENO);

    // The viewer, one connection for all the renders of this command (on the root, which holds the summed film).
    std::unique_ptr<DisplayServer> display;
    if (root && !o.display_server.empty())
        display = std::make_unique<DisplayServer>(*parse_display_address(o.display_server),
                                                  [](const std::string& message) { fmt::print(stderr, "pathlab: warning: {}\n", message); });

    InterruptGuard interrupt;
    // A scene that fails (too large for memory, a full disk) is reported and the others still
    // render; the exit code is then 1.
    size_t failed = 0;
    for (size_t j = 0; j < jobs.size(); ++j) {
        RenderJob& job = jobs[j];
        job.settings.progress = show_progress;
        job.settings.cancel = &InterruptGuard::flag();
        job.settings.ranks = &group;
        // The scene, and the estimator when there are several.
        const std::string name =
            job.scene_choice().name + (several_algorithms ? " / " + job.integrator_info().name : std::string());
        if (!o.display_server.empty()) {
            // Every rank takes part in summing the films for it; the root sends the sum.
            const std::string title = job.scene_choice().name + " / " + job.integrator_info().name;
            // With --aovs, their layers too, and the integrator's own images (the display is
            // called between rounds, when no pass is adding to them).
            job.settings.display = [&display, &job, title, distributed](const Film& film, const RenderStats&) {
                if (!display) return;
                DisplayFrame frame = film_frame(title, film);
                add_frame_channels(frame, render_aov_channels(job.aovs(), film, job.aov_film()));
                // bdpt's per-strategy images (the root's own part only across processes: left out there)
                if (!distributed) add_frame_channels(frame, job.integrator().display_channels());
                display->post(std::move(frame));
            };
        }
        if (show_progress) fmt::print(stderr, "{} / {}\n", job.scene_choice().name, job.integrator_info().name);

        // Every rank loads the scene from the same path and makes its film; the root takes up
        // the checkpoint to resume.
        RenderResult result;
        RenderIdentity identity;
        std::string done_text;
        double seconds_before = 0;
        int width = 0, height = 0;
        {
            int code = 0;
            std::string message;
            try {
                const Scene& scene = job.scene();
                width = job.settings.width > 0 ? job.settings.width : scene.default_width();
                height = job.settings.height > 0 ? job.settings.height : scene.default_height();
                identity = render_identity(job, width, height);
                if (root && !resumes[j].empty()) {
                    ResumedRender resumed = resume_checkpoint(resumes[j], job, identity);
                    result.film = std::move(resumed.film);
                    done_text = resumed.done.to_string();
                    seconds_before = resumed.seconds;
                } else {
                    result.film = make_film(width, height);
                }
            } catch (const UsageError& e) {
                code = 2, message = e.what();
            } catch (const CheckpointError& e) {
                code = 2, message = e.what();
            } catch (const std::exception& e) {
                code = 1, message = fmt::format("error: {}: {}", name, e.what());
            }
            std::string messages;
            code = group.agree(code, message, &messages);
            if (code == 2) {
                if (root) print_messages(messages);
                return 2;
            }
            if (code) {
                if (root) print_messages(messages);
                ++failed;
                continue;
            }
        }
        group.broadcast_text(done_text);
        job.settings.done = *PassSet::parse(done_text);
        if (!checkpoints[j].empty()) {
            const std::string command =
                checkpoint_command(job.scene_choice(), o.algorithm_given ? job.integrator_info().name : "", o.given);
            checkpoint_job(job, checkpoints[j], CheckpointInfo{identity, {}, width, height, seconds_before, PATHLAB_VERSION, command}, name);
        }
        try {
            result.stats = job.run_into(result.film);
        } catch (const std::exception& e) {
            fmt::print(stderr, "pathlab: error: {}{}: {}\n", distributed ? group.name() + ": " : "", name, e.what());
            if (distributed) group.abort(1);
            ++failed;
            continue;
        }
        const RenderStats& s = result.stats;
        if (root) {
            try {
                job.write_outputs(result, o.exposure, render_metadata(identity, s.passes, s.invalid_samples, s.integrator));
                if (!o.stats_path.empty()) write_stats(job.expand(o.stats_path), job, result, threads, group.size());
            } catch (const std::exception& e) {
                fmt::print(stderr, "pathlab: error: {}: {}\n", name, e.what());
                ++failed;
                continue;
            }
            if (!o.quiet) print_summary(job, name, s);
            if (const std::string why = final_checkpoint_failure(checkpoints[j], s); !why.empty()) {
                // The image is written, but the checkpoint asked for does not hold this render's end.
                fmt::print(stderr, "pathlab: error: {}: {}\n", name, why);
                ++failed;
                if (s.interrupted) return 1;
                continue;
            }
        }
        if (s.interrupted) {
            if (root && j + 1 < jobs.size()) fmt::print(stderr, "pathlab: interrupted; {} render(s) not done\n", jobs.size() - j - 1);
            return interrupted_exit_code();
        }
    }
    if (root && failed && jobs.size() > 1) fmt::print(stderr, "pathlab: {} of {} renders failed\n", failed, jobs.size());
    return failed ? 1 : 0;
}

}  // namespace pathlab
