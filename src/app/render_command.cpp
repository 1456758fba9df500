#include "app/render_command.hpp"

#include <tbb/global_control.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <filesystem>

#include <fmt/format.h>

#include "app/command_arguments.hpp"
#include "app/interrupt.hpp"
#include "job/usage_error.hpp"
#include "image/image_io.hpp"
#include "job/output_paths.hpp"
#include "job/render_job.hpp"


namespace pathlab {
namespace {

constexpr int kDefaultSpp = 64;
const char* const kDefaultOutputs[] = {"out/{index}-{scene}-{algorithm}.exr", "out/{index}-{scene}-{algorithm}.png"};

void write_stats(const std::string& path, RenderJob& job, const RenderResult& r, int threads) {
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
        {"threads", threads},
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
    app.add_option("--seed", o.seed, "Random seed, 0 to 18446744073709551615; the image is a pure function of it")
        ->capture_default_str();
    app.add_option("--sampler", o.sampler,
                   "Random numbers: 'independent' (PCG32; the course's setting, exact per-pixel standard errors) or "
                   "'sobol' (scrambled low-discrepancy points: lower error at equal time)")
        ->capture_default_str();
    add_threads_option(app, o.threads);
    app.add_option("-o,--output", o.outputs,
                   "Output file, repeatable; format by extension: .exr .hdr .pfm .png. Placeholders {scene} {index} "
                   "{algorithm}. Default: out/{index}-{scene}-{algorithm}.exr and .png");
    app.add_option("--exposure", o.exposure, "Exposure in stops for .png output")->capture_default_str();
    app.add_option("--stats", o.stats_path, "Write render statistics as JSON (placeholders as for -o)");
    app.add_option_function<int>("--max-depth", [&o](const int& v) { o.max_depth = v, o.max_depth_given = true; },
                                 "Longest path in bounces (-1: unlimited; default: the scene file's, else -1)");
    app.add_option_function<int>("--rr-depth", [&o](const int& v) { o.rr_depth = v, o.rr_depth_given = true; },
                                 "Bounces before Russian roulette starts (default: the scene file's, else 3)");
    app.add_option("--mis", o.mis, "bdpt, vcm, bpm: the MIS heuristic, balance or power")->capture_default_str();
    app.add_option("--strategies", o.strategies_dir,
                   "bdpt: also write one image per strategy (s, t), weighted and unweighted, and montages, into this directory "
                   "(placeholders as for -o)");
    app.add_option("--strategies-depth", o.strategies_depth, "bdpt: ... for paths of up to this many bounces")->capture_default_str();
    app.add_option("--photons", o.photons, "sppm, ppm: light paths per iteration (default one per pixel); pm: light paths of its maps (8 per pixel)");
    app.add_option("--radius", o.photon_radius,
                   "sppm, ppm, vcm, bpm: the first iteration's photon radius (default two pixel footprints at the scene's centre); pm: a fixed "
                   "radius instead of the k nearest");
    app.add_option("--alpha", o.photon_alpha, "sppm, ppm, vcm, bpm: the radius reduction, in (0, 1] (default 2/3)");
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
    app.add_flag("-q,--quiet", o.quiet, "No progress line and no summary");
}

int run_render_command(const RenderCommandOptions& o) {
    if (o.algorithm_given) integrator_or_usage_error(o.algorithm);
    SceneDefines defines;
    for (const std::string& d : o.defines) {
        const size_t eq = d.find('=');
        if (eq == std::string::npos || eq == 0)
            throw UsageError(fmt::format("invalid -D '{}': expected name=value", d));
        defines[d.substr(0, eq)] = d.substr(eq + 1);
    }
    JobRequest request;
    if (o.algorithm_given) request.algorithm = o.algorithm;
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
    if (o.mis != "balance" && o.mis != "power")
        throw UsageError(fmt::format("unknown MIS heuristic '{}'. Valid heuristics: balance, power", o.mis));
    request.mis_power = o.mis == "power";
    request.strategies_depth = o.strategies_depth;
    request.photons = o.photons;
    request.photon_radius = o.photon_radius;
    request.photon_alpha = o.photon_alpha;
    request.vcm_merging = !o.no_merging;
    request.vcm_connections = !o.no_connections;
    if (o.ic_rays && (*o.ic_rays < 4 || *o.ic_rays > 65536)) throw UsageError(fmt::format("--ic-rays must be 4 to 65536, got {}", *o.ic_rays));
    if (o.ic_error && !(*o.ic_error >= 0 && *o.ic_error <= 10)) throw UsageError(fmt::format("--ic-error must be 0 to 10, got {}", *o.ic_error));
    request.ic_rays = o.ic_rays;
    request.ic_error = o.ic_error;
    if (o.ic_no_gradients) request.ic_gradients = false;
    const auto in_range = [](const char* name, const auto& v, double lo, double hi) {
        if (v && !(double(*v) >= lo && double(*v) <= hi)) throw UsageError(fmt::format("{} must be {:g} to {:g}, got {}", name, lo, hi, *v));
    };
    in_range("--pbgi-surfels", o.pbgi_surfels, 1, 1e7);
    in_range("--pbgi-cutoff", o.pbgi_cutoff, 0, 4 * kPi);
    in_range("--pbgi-bounces", o.pbgi_bounces, 1, 64);
    in_range("--pbgi-resolution", o.pbgi_resolution, 2, 256);
    in_range("--pbgi-direct-samples", o.pbgi_direct_samples, 1, 65536);
    in_range("--pbgi-spacing", o.pbgi_spacing, 1, 64);
    request.pbgi_surfels = o.pbgi_surfels;
    request.pbgi_cutoff = o.pbgi_cutoff;
    request.pbgi_bounces = o.pbgi_bounces;
    request.pbgi_resolution = o.pbgi_resolution;
    request.pbgi_direct_samples = o.pbgi_direct_samples;
    request.pbgi_spacing = o.pbgi_spacing;
    if (o.no_merging && o.no_connections) throw UsageError("--no-merging and --no-connections together leave vcm no strategy");

    std::vector<RenderJob> jobs;
    for (SceneChoice& choice : resolve_scenes(o.scene, defines)) jobs.emplace_back(std::move(choice), request);

    std::vector<std::string> patterns(o.outputs.begin(), o.outputs.end());
    if (patterns.empty()) patterns.assign(std::begin(kDefaultOutputs), std::end(kDefaultOutputs));
    // Check every output before the first render starts: writable, not an input, not another output.
    OutputPaths paths;
    for (const RenderJob& job : jobs)
        if (!job.scene_choice().file.empty()) paths.input(job.scene_choice().file, "the scene file");
    for (size_t j = 0; j < jobs.size(); ++j) {
        for (const std::string& p : patterns) jobs[j].outputs.push_back(jobs[j].expand(p));
        for (size_t k = 0; k < j; ++k)
            for (const std::string& path : jobs[j].outputs)
                if (std::find(jobs[k].outputs.begin(), jobs[k].outputs.end(), path) != jobs[k].outputs.end())
                    throw UsageError(fmt::format("scenes {} and {} would both write {}: add {{scene}} or {{index}} to -o",
                                                 jobs[k].scene_choice().name, jobs[j].scene_choice().name, path));
        for (const std::string& path : jobs[j].outputs) paths.output(path, "the output", /*image=*/true);
        if (!o.stats_path.empty()) paths.output(jobs[j].expand(o.stats_path), "--stats", /*image=*/false);
        const std::string& algorithm = jobs[j].integrator_info().name;
        const auto one_of = [&algorithm](std::initializer_list<const char*> names) {
            for (const char* n : names)
                if (algorithm == n) return true;
            return false;
        };
        if (o.photons && !one_of({"sppm", "ppm", "pm"}))
            throw UsageError(fmt::format("--photons sets the light paths of sppm, ppm and pm; {} has no such count", algorithm));
        if (o.photon_radius && !one_of({"sppm", "ppm", "pm", "vcm", "bpm"}))
            throw UsageError(fmt::format("--radius sets the photon radius of sppm, ppm, pm, vcm and bpm; {} has none", algorithm));
        if (o.photon_alpha && !one_of({"sppm", "ppm", "vcm", "bpm"}))
            throw UsageError(fmt::format("--alpha is the radius reduction of sppm, ppm, vcm and bpm, not {}'s", algorithm));
        if (o.mis == "power" && !one_of({"bdpt", "vcm", "bpm"}))
            throw UsageError(fmt::format("--mis chooses the heuristic of bdpt, vcm and bpm; {} has its own", algorithm));
        const bool ic_options = o.ic_rays || o.ic_error || o.ic_no_gradients || !o.ic_records.empty();
        if (ic_options && algorithm != "ic")
            throw UsageError(fmt::format("--ic-rays, --ic-error, --ic-no-gradients and --ic-records are ic's, not {}'s", algorithm));
        const bool pbgi_options =
            o.pbgi_surfels || o.pbgi_cutoff || o.pbgi_bounces || o.pbgi_resolution || o.pbgi_direct_samples || o.pbgi_spacing;
        if (pbgi_options && algorithm != "pbgi")
            throw UsageError(fmt::format(
                "--pbgi-surfels, --pbgi-cutoff, --pbgi-bounces, --pbgi-resolution, --pbgi-direct-samples and --pbgi-spacing are pbgi's, not {}'s",
                algorithm));
        if (!o.ic_records.empty()) {
            const std::string p = jobs[j].expand(o.ic_records);
            paths.output(p, "--ic-records", /*image=*/true);
            jobs[j].integrator_options().ic_records_path = p;
        }
        if ((o.no_merging || o.no_connections) && algorithm != "vcm")
            throw UsageError(fmt::format("--no-merging and --no-connections switch off vcm's strategies, not {}'s", algorithm));
        if (!o.strategies_dir.empty()) {
            if (jobs[j].integrator_info().name != "bdpt")
                throw UsageError(fmt::format("--strategies writes the strategies of bdpt, not of {}", jobs[j].integrator_info().name));
            const std::string dir = jobs[j].expand(o.strategies_dir);
            paths.output((std::filesystem::path(dir) / "montage-weighted.png").string(), "--strategies", /*image=*/true);
            jobs[j].integrator_options().strategies_dir = dir;
        }
    }

    std::optional<tbb::global_control> thread_limit;
    if (o.threads != 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, thread_count_or_cap(o.threads));
    const int threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

    const bool show_progress = !o.quiet && isatty(STDERR_FILENO);

    InterruptGuard interrupt;
    // A scene that fails (too large for memory, a full disk) is reported and the others still
    // render; the exit code is then 1.
    size_t failed = 0;
    for (size_t j = 0; j < jobs.size(); ++j) {
        RenderJob& job = jobs[j];
        job.settings.progress = show_progress;
        job.settings.cancel = &InterruptGuard::flag();
        const std::string& name = job.scene_choice().name;
        if (show_progress) fmt::print(stderr, "{} / {}\n", name, job.integrator_info().name);
        RenderResult result;
        try {
            result = job.run();
            job.write_outputs(result, o.exposure);
            if (!o.stats_path.empty()) write_stats(job.expand(o.stats_path), job, result, threads);
        } catch (const UsageError&) {
            throw;
        } catch (const std::exception& e) {
            fmt::print(stderr, "pathlab: error: {}: {}\n", name, e.what());
            ++failed;
            continue;
        }
        const RenderStats& s = result.stats;
        if (!o.quiet)
            fmt::print(stderr, "{}: {} spp in {:.2f}s ({:.2f} Msamples/s, {:.2f} Mrays/s){}{} -> {}\n", name, s.spp,
                       s.seconds, s.seconds > 0 ? double(s.samples) / s.seconds * 1e-6 : 0.0,
                       s.seconds > 0 ? double(s.rays) / s.seconds * 1e-6 : 0.0,
                       s.invalid_samples ? fmt::format(", {} NaN/Inf samples discarded", s.invalid_samples) : "",
                       s.integrator.empty() ? "" : fmt::format(", {}", fmt::join([&] {
                           std::vector<std::string> parts;
                           for (const IntegratorStatistic& x : s.integrator) parts.push_back(fmt::format("{} {:g}", x.name, x.value));
                           return parts;
                       }(), ", ")),
                       fmt::join(job.outputs, ", "));
        if (s.interrupted) {
            if (j + 1 < jobs.size()) fmt::print(stderr, "pathlab: interrupted; {} scene(s) not rendered\n", jobs.size() - j - 1);
            return interrupted_exit_code();
        }
    }
    if (failed && jobs.size() > 1) fmt::print(stderr, "pathlab: {} of {} scenes failed\n", failed, jobs.size());
    return failed ? 1 : 0;
}

}  // namespace pathlab
