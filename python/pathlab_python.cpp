// The Python module `pathlab` (pybind11 + NumPy): scenes, estimators, renders as float32 arrays
// of shape (height, width, 3), compare's statistics, image files. A render is the command
// line's RenderJob with the same settings, so it gives the same bytes as `pathlab SCENE ...`.
//
//   import pathlab
//   scene = pathlab.load("scenes/example.xml", defines={"spp": "16"})   # or load(3), load("ceiling-glossy")
//   img, stderr = pathlab.render(scene, algorithm="pt-mis", spp=64, seed=1, threads=0)
//   stats = pathlab.compare(img, reference)          # as `pathlab compare --json`
//   pathlab.write("out.exr", img)
//
// While rendering, the GIL is released (other Python threads run) and Ctrl-C is honoured: the
// render stops after its current batch of passes and KeyboardInterrupt is raised. A render takes
// the command line's --first-sample, --checkpoint, --checkpoint-every and --resume too (the job
// layer's checks and files: job/job_checkpoint.hpp), so renders of disjoint sample ranges merge
// with `pathlab merge`, and `pathlab --resume FILE` continues a Python render's checkpoint.
#include <pybind11/pybind11.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <limits>
#include <map>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "app/resumed_command.hpp"
#include "image/image_io.hpp"
#include "integrators/integrator.hpp"
#include "job/extra_channels.hpp"
#include "job/job_checkpoint.hpp"
#include "job/render_identity.hpp"
#include "job/render_job.hpp"
#include "lights/light_sampler.hpp"
#include "job/scene_choice.hpp"
#include "job/usage_error.hpp"
#include "diff/loss.hpp"
#include "diff/optimization.hpp"
#include "diff/parameters.hpp"
#include "diff/path_replay.hpp"
#include "judge/image_compare.hpp"
#include "judge/image_compare_json.hpp"
#include "scene/builtin_scenes.hpp"
#include "scene/scene.hpp"

namespace py = pybind11;
using namespace pathlab;

namespace {

// A loaded scene: what the command line resolves from a name or a file, and its built form
// (the accelerator), made at the first render and shared by the later ones.
struct PyScene {
    SceneChoice choice;
    std::shared_ptr<const Scene> built;
};

std::string scene_names() {
    std::string s;
    for (const BuiltinSceneInfo& b : builtin_scenes()) s += fmt::format("{}{} {}", s.empty() ? "" : ", ", b.index, b.name);
    return s;
}

std::string algorithm_names() {
    std::string s;
    for (const IntegratorInfo& e : integrators()) s += (s.empty() ? "" : ", ") + e.name;
    return s;
}

// The name of a value's type, for TypeErrors ("float", "str").
std::string type_name(const py::handle& v) { return py::str(py::type::of(v).attr("__name__")).cast<std::string>(); }

// A usage problem from the C++ side is a ValueError (an unknown name, a malformed file).
template <typename F>
auto translating(F&& f) {
    try {
        return f();
    } catch (const UsageError& e) {
        throw py::value_error(e.what());
    } catch (const ImageIoError& e) {
        throw py::value_error(e.what());
    }
}

// A file name given as a str or a path (os.PathLike); None: "".
std::string path_argument(const py::object& v, const char* name) {
    if (v.is_none()) return "";
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::hasattr(v, "__fspath__")) return py::str(v.attr("__fspath__")()).cast<std::string>();
    throw py::type_error(fmt::format("{} must be a file name (str or path), not {}", name, type_name(v)));
}

std::shared_ptr<PyScene> py_load(const py::object& what, const std::map<std::string, std::string>& defines) {
    std::string spec;
    if (py::isinstance<py::bool_>(what)) {
        throw py::type_error("scene must be a course index (int 0-7), a scene name or a scene file (str); valid scenes: " + scene_names());
    } else if (py::isinstance<py::int_>(what)) {
        spec = std::to_string(what.cast<long long>());
    } else if (py::isinstance<py::str>(what)) {
        spec = what.cast<std::string>();
    } else if (py::hasattr(what, "__fspath__")) {
        spec = py::str(what.attr("__fspath__")()).cast<std::string>();
    } else {
        throw py::type_error(fmt::format("scene must be a course index (int 0-7), a scene name or a scene file (str or path), not {}; "
                                         "valid scenes: {}, or a scene file ending in .xml (or a glTF scene: .gltf, .glb)",
                                         type_name(what), scene_names()));
    }
    if (spec.empty() || spec == "all" || spec.find(',') != std::string::npos)
        throw py::value_error("load() takes one scene: a course index, a name (" + scene_names() + ") or a scene file");
    std::vector<SceneChoice> scenes = translating([&] { return resolve_scenes(spec, defines); });
    return std::make_shared<PyScene>(PyScene{std::move(scenes.front()), nullptr});
}

std::shared_ptr<PyScene> scene_argument(const py::object& scene) {
    if (py::isinstance<PyScene>(scene)) return scene.cast<std::shared_ptr<PyScene>>();
    return py_load(scene, {});
}

std::string string_argument(const py::object& v, const char* name, const std::string& valid) {
    if (!py::isinstance<py::str>(v))
        throw py::type_error(fmt::format("{} must be a str, not {}; valid: {}", name, type_name(v),
                                         valid));
    return v.cast<std::string>();
}

// An int argument within [lo, hi] (None: absent): another type is a TypeError, an int outside
// the range a ValueError naming it (pybind11's own conversion called -1 or 2**64 a wrong type).
template <typename T>
std::optional<T> int_argument(const py::object& v, const char* name, T lo, T hi, const char* why = "") {
    if (v.is_none()) return std::nullopt;
    if (!py::isinstance<py::int_>(v) || py::isinstance<py::bool_>(v))
        throw py::type_error(fmt::format("{} must be an int, not {}", name, type_name(v)));
    const py::int_ low(lo), high(hi);
    if (v < low || v > high) throw py::value_error(fmt::format("{} must be an int from {} to {}{}, not {}", name, lo, hi, why, py::str(v).cast<std::string>()));
    return v.cast<T>();
}

// An image as a float32 array of shape (height, width, 3) that owns its copy of the pixels.
py::array_t<float> to_array(const Image& img) {
    py::array_t<float> a({py::ssize_t(img.height()), py::ssize_t(img.width()), py::ssize_t(3)});
    std::copy(img.data(), img.data() + img.pixel_count() * 3, a.mutable_data());
    return a;
}

// An (H, W, 3) array of numbers (any float or int dtype, converted to float32), or an image file.
Image to_image(const py::object& v, const char* name) {
    if (py::isinstance<py::str>(v) || py::hasattr(v, "__fspath__")) {
        const std::string path = path_argument(v, name);
        return translating([&] { return read_image(path); });
    }
    if (!py::isinstance<py::array>(v) && !py::isinstance<py::list>(v))
        throw py::type_error(fmt::format("{} must be a NumPy array of shape (height, width, 3) or an image file name (str), not {}", name,
                                         type_name(v)));
    py::array_t<float, py::array::c_style | py::array::forcecast> a;
    try {
        a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(v);
    } catch (const py::error_already_set&) {
        a = {};
    }
    if (!a) throw py::type_error(fmt::format("{} must be an array of numbers of shape (height, width, 3)", name));
    if (a.ndim() != 3 || a.shape(2) != 3 || a.shape(0) < 1 || a.shape(1) < 1)
        throw py::value_error(fmt::format("{} must have shape (height, width, 3), not {}", name,
                                          py::str(py::tuple(py::cast(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim())))).cast<std::string>()));
    Image img(int(a.shape(1)), int(a.shape(0)));
    std::copy(a.data(), a.data() + img.pixel_count() * 3, img.data());
    return img;
}

// Runs `work` (the job's render) on a worker thread while this (Python's) thread, with the GIL
// released, waits and every 20 ms lets Python run its signal handlers: a KeyboardInterrupt (or
// any exception a handler raises) cancels the render after its current batch of passes and is
// raised here.
void run_interruptibly(RenderJob& job, const std::function<void()>& work) {
    std::atomic<bool> cancel{false};
    job.settings.cancel = &cancel;
    std::mutex m;
    std::condition_variable cv;
    bool done = false;
    std::exception_ptr failure;
    bool python_error = false;
    {
        py::gil_scoped_release release;
        std::thread worker([&] {
            try {
                work();
            } catch (...) {
                failure = std::current_exception();
            }
            std::lock_guard<std::mutex> lock(m);
            done = true;
            cv.notify_all();
        });
        std::unique_lock<std::mutex> lock(m);
        while (!done) {
            cv.wait_for(lock, std::chrono::milliseconds(20));
            if (done || python_error) continue;
            lock.unlock();
            {
                py::gil_scoped_acquire acquire;
                if (PyErr_CheckSignals() != 0) {
                    python_error = true;  // the error stays set until it is raised below
                    cancel = true;
                }
            }
            lock.lock();
        }
        lock.unlock();
        worker.join();
    }
    if (python_error) throw py::error_already_set();
    if (failure) {
        try {
            std::rethrow_exception(failure);
        } catch (const UsageError& e) {
            throw py::value_error(e.what());
        } catch (const CheckpointError& e) {
            throw py::value_error(e.what());
        }
    }
}

// The command line's estimator options by their names without dashes (mis="power", photons=...,
// no_merging=True, ic_rays=..., pbgi_surfels=...; --first-sample, --checkpoint and --resume are
// render()'s own keyword arguments). RenderJob refuses one the estimator does not take, as on the
// command line.
void apply_estimator_options(JobRequest& r, const py::kwargs& options) {
    constexpr int kIntMax = std::numeric_limits<int>::max();
    static const char* const kNames =
        "mis, photons, radius, alpha, volume_estimate, no_merging, no_connections, ic_rays, ic_error, ic_no_gradients, pbgi_surfels, "
        "pbgi_cutoff, pbgi_bounces, pbgi_resolution, pbgi_direct_samples, pbgi_spacing, guiding_spp, guiding_rr, guiding_fraction, guiding, estimators, photon_beams, beam_radius, "
        "null_depth";
    const auto number = [](const py::handle& v, const std::string& name) {
        if (!py::isinstance<py::int_>(v) && !py::isinstance<py::float_>(v))
            throw py::type_error(fmt::format("{} must be a number, not {}", name, type_name(v)));
        const double x = v.cast<double>();
        if (!std::isfinite(x)) throw py::value_error(fmt::format("{} must be finite", name));
        return x;
    };
    const auto flag = [](const py::handle& v, const std::string& name) {
        if (!py::isinstance<py::bool_>(v)) throw py::type_error(fmt::format("{} must be True or False", name));
        return v.cast<bool>();
    };
    static const std::map<std::string, std::optional<int> JobRequest::*> int_options = {
        {"pbgi_surfels", &JobRequest::pbgi_surfels},       {"pbgi_bounces", &JobRequest::pbgi_bounces},
        {"pbgi_resolution", &JobRequest::pbgi_resolution}, {"pbgi_direct_samples", &JobRequest::pbgi_direct_samples},
        {"pbgi_spacing", &JobRequest::pbgi_spacing},       {"guiding_spp", &JobRequest::guiding_spp}};
    for (const auto& [key, value] : options) {
        const std::string name = py::str(key);
        const py::object v = py::reinterpret_borrow<py::object>(value);
        if (name == "mis") {
            const std::string m = string_argument(v, "mis", "balance, power");
            if (m != "balance" && m != "power") throw py::value_error(fmt::format("unknown mis '{}'; valid: balance, power", m));
            r.mis_power = m == "power";
        } else if (name == "null_depth") {
            const std::string m = string_argument(v, "null_depth", "count, skip");
            if (m != "count" && m != "skip") throw py::value_error(fmt::format("unknown null_depth '{}'; valid: count, skip", m));
            r.skip_null_events = m == "skip";
        } else if (name == "beam_radius") {
            r.beam_radius = float(number(v, name));
        } else if (name == "photon_beams") {
            r.photon_beams = *int_argument<int64_t>(v, "photon_beams", 0, int64_t(1) << 40);
        } else if (name == "photons") {
            r.photons = *int_argument<int64_t>(v, "photons", 0, int64_t(1) << 40);
        } else if (name == "radius") {
            r.photon_radius = float(number(v, name));
        } else if (name == "alpha") {
            r.photon_alpha = number(v, name);
        } else if (name == "volume_estimate") {
            const std::string e = string_argument(v, "volume_estimate", "beam, points");
            if (e != "beam" && e != "points") throw py::value_error(fmt::format("unknown volume_estimate '{}'; valid: beam, points", e));
            r.volume_beam = e == "beam";
        } else if (name == "no_merging") {
            r.vcm_merging = !flag(v, name);
        } else if (name == "guiding_rr") {
            r.guiding_rr = flag(v, name);
        } else if (name == "guiding_fraction") {
            r.guiding_fraction = py::isinstance<py::str>(v) ? std::string(py::str(v)) : fmt::format("{}", number(v, name));
        } else if (name == "guiding") {
            r.guiding = string_argument(v, "guiding", "sd-tree or vmm");
        } else if (name == "estimators") {
            r.estimators = string_argument(v, "estimators", "a comma-separated list of bpt, surf, pp3d, pb2d, bb1d");
        } else if (name == "no_connections") {
            r.vcm_connections = !flag(v, name);
        } else if (name == "ic_rays") {
            r.ic_rays = *int_argument<int>(v, "ic_rays", 0, kIntMax);
        } else if (name == "ic_error") {
            r.ic_error = float(number(v, name));
        } else if (name == "ic_no_gradients") {
            if (flag(v, name)) r.ic_gradients = false;
        } else if (name == "pbgi_cutoff") {
            r.pbgi_cutoff = float(number(v, name));
        } else if (const auto field = int_options.find(name); field != int_options.end()) {
            r.*(field->second) = *int_argument<int>(v, name.c_str(), 0, kIntMax);
        } else {
            throw py::type_error(fmt::format("render() got an unexpected keyword argument '{}'; the estimators' options: {}", name, kNames));
        }
    }
}

// The command line's options for a render's arguments, which its checkpoints record (with its
// scene) so that `pathlab --resume FILE` alone continues it (app/resumed_command.hpp).
OptionGroups command_options(const RenderJob& job, const JobRequest& r, bool algorithm_given, bool resolution_given, int threads,
                             const py::kwargs& estimator_options) {
    OptionGroups given;
    const auto option = [&](const char* name, const std::string& value) { given.push_back({name, value}); };
    for (const auto& [name, value] : job.scene_choice().parameters) option("--define", name + "=" + value);
    if (algorithm_given) option("--algorithm", job.integrator_info().name);
    if (r.spp) option("--spp", fmt::format("{}", *r.spp));
    if (r.time_limit > 0) option("--time", fmt::format("{}", r.time_limit));
    if (resolution_given) option("--resolution", fmt::format("{}x{}", r.width, r.height));
    option("--seed", fmt::format("{}", r.seed));
    option("--sampler", r.sampler == SamplerKind::Sobol ? "sobol" : "independent");
    if (r.spectral) given.push_back({"--spectral"});
    if (r.max_depth) option("--max-depth", fmt::format("{}", *r.max_depth));
    if (r.rr_depth) option("--rr-depth", fmt::format("{}", *r.rr_depth));
    if (r.light_sampler) option("--light-sampler", light_sampler_name(*r.light_sampler));
    if (r.ris_candidates) option("--ris-candidates", fmt::format("{}", *r.ris_candidates));
    if (r.light_split) option("--light-split", fmt::format("{}", *r.light_split));
    if (threads > 0) option("--threads", fmt::format("{}", threads));
    // The estimators' options by their command-line names (checked by apply_estimator_options).
    for (const auto& [key, value] : estimator_options) {
        std::string name = "--" + py::str(key).cast<std::string>();
        std::replace(name.begin(), name.end(), '_', '-');
        if (py::isinstance<py::bool_>(value)) {
            if (value.cast<bool>()) given.push_back({name});
        } else {
            option(name.c_str(), py::str(value).cast<std::string>());
        }
    }
    if (r.first_sample > 0) option("--first-sample", fmt::format("{}", r.first_sample));
    if (r.checkpoint_every != kDefaultCheckpointEvery) option("--checkpoint-every", fmt::format("{}", r.checkpoint_every));
    return given;
}

py::tuple py_render(const py::object& scene_obj, const py::object& algorithm, const py::object& spp_arg, const py::object& seed_arg,
                 const py::object& threads_arg, double time, const py::object& resolution, const py::object& max_depth_arg,
                 const py::object& sampler, bool spectral, const py::object& rr_depth_arg, const py::object& light_sampler,
                 const py::object& ris_candidates_arg, const py::object& light_split_arg, const py::object& first_sample_arg, const py::object& checkpoint_arg,
                 double checkpoint_every, const py::object& resume_arg, const py::object& aovs_arg, const py::kwargs& estimator_options) {
    constexpr int kIntMax = std::numeric_limits<int>::max();
    // As the command line: sample indices from 2^62 on are refused (such a render never ends);
    // first_sample + spp past them are refused by RenderJob, with the command line's message.
    const std::optional<uint64_t> spp = int_argument<uint64_t>(spp_arg, "spp", 1, kMaxSampleIndex - 1, " (sample indices end at 2^62)");
    const uint64_t first_sample = *int_argument<uint64_t>(first_sample_arg, "first_sample", 0, std::numeric_limits<uint64_t>::max());
    const std::string checkpoint_pattern = path_argument(checkpoint_arg, "checkpoint"), resume_pattern = path_argument(resume_arg, "resume");
    const uint64_t seed = *int_argument<uint64_t>(seed_arg, "seed", 0, std::numeric_limits<uint64_t>::max());
    const int threads = *int_argument<int>(threads_arg, "threads", 0, kIntMax);
    const std::optional<int> max_depth = int_argument<int>(max_depth_arg, "max_depth", -1, kIntMax);
    const std::optional<int> rr_depth = int_argument<int>(rr_depth_arg, "rr_depth", 0, kIntMax);
    const std::optional<int> ris_candidates = int_argument<int>(ris_candidates_arg, "ris_candidates", 1, kIntMax);
    std::shared_ptr<PyScene> scene = scene_argument(scene_obj);
    JobRequest request;
    if (!algorithm.is_none()) {
        const std::string name = string_argument(algorithm, "algorithm", algorithm_names());
        request.algorithm = translating([&] { return integrator_or_usage_error(name).name; });
    }
    if (spp) request.spp = *spp;
    if (time < 0 || !std::isfinite(time)) throw py::value_error("time must be a positive number of seconds (0: none)");
    request.time_limit = time;
    request.seed = seed;
    request.max_depth = max_depth;
    // As the command line's --spectral, --rr-depth, --light-sampler and --ris-candidates (RenderJob
    // refuses what an estimator does not do, as there).
    request.spectral = spectral;
    request.rr_depth = rr_depth;
    if (!light_sampler.is_none()) {
        const std::string name = string_argument(light_sampler, "light_sampler", kLightSamplerNames);
        request.light_sampler = parse_light_sampler(name);
        if (!request.light_sampler) throw py::value_error(fmt::format("unknown light sampler '{}'; valid: {}", name, kLightSamplerNames));
    }
    request.ris_candidates = ris_candidates;
    if (!light_split_arg.is_none()) {
        const double split = light_split_arg.cast<double>();
        if (!(split >= 0) || !(split <= kMaxLightSplit))
            throw py::value_error(fmt::format("light_split must be between 0 (no splitting) and {}", kMaxLightSplit));
        request.light_split = float(split);
    }
    apply_estimator_options(request, estimator_options);
    if (!resolution.is_none()) {
        const auto size = py::isinstance<py::tuple>(resolution) || py::isinstance<py::list>(resolution)
                              ? std::optional<std::vector<int>>(resolution.cast<std::vector<int>>())
                              : std::nullopt;
        if (!size || size->size() != 2) throw py::type_error("resolution must be a (width, height) pair of ints");
        if ((*size)[0] < 1 || (*size)[1] < 1) throw py::value_error("resolution must be positive");
        request.width = (*size)[0], request.height = (*size)[1];
    }
    const std::string sampler_name = string_argument(sampler, "sampler", "independent, sobol");
    if (sampler_name != "independent" && sampler_name != "sobol")
        throw py::value_error(fmt::format("unknown sampler '{}'; valid: independent, sobol", sampler_name));
    request.sampler = sampler_name == "sobol" ? SamplerKind::Sobol : SamplerKind::Independent;
    // --first-sample and --checkpoint-every: RenderJob checks them, as for the command line.
    request.first_sample = first_sample;
    request.checkpoint_every = checkpoint_every;
    // aovs: a list of names or a comma-separated string, as --aovs.
    if (!aovs_arg.is_none()) {
        request.aovs = py::isinstance<py::str>(aovs_arg) ? split_comma_list(aovs_arg.cast<std::string>()) : aovs_arg.cast<std::vector<std::string>>();
        if (!checkpoint_pattern.empty() || !resume_pattern.empty() || first_sample != 0)
            throw py::value_error("aovs cannot be checkpointed, resumed or split by first_sample yet: render them in one go");
    }

    // The scene's BVH is built once and shared by its renders with the default light sampler in
    // RGB; another light sampler, or spectral mode (which checks the scene's materials first),
    // builds the scene for that render.
    std::optional<RenderJob> job;
    translating([&] {
        job.emplace(scene->choice, request);
        const IntegratorOptions& o = job->integrator_options();
        if (o.spectral || o.light_sampler != LightSamplerKind::Power) return;
        if (!scene->built) scene->built = std::shared_ptr<const Scene>(Scene::build(scene->choice.description));
        job.emplace(scene->choice, request, scene->built);
    });
    // --checkpoint and --resume: the files (placeholders expanded) checked as the command line
    // checks them. A scene changed by update() hashes as the file's scene (its materials are not
    // in the hash), so its checkpoints would mix with the file's: refused.
    std::string checkpoint, resume;
    translating([&] {
        resume = resume_pattern.empty() ? "" : job->expand(resume_pattern);
        const std::string given = checkpoint_pattern.empty() ? "" : job->expand(checkpoint_pattern);
        checkpoint = checkpoint_file(given, resume);
        if (!checkpoint.empty() && scene->choice.hash.empty())
            throw UsageError("checkpoint and resume take a scene as loaded: a scene changed by pathlab.update() has the file's "
                             "identity, so its checkpoints would be taken for the file's (give the values to the file as $parameters, "
                             "with load(..., defines=))");
        OutputPaths paths;
        paths.scene_inputs(scene->choice);
        add_resume_input(paths, given, resume);
        add_checkpoint_output(paths, given, resume);
    });
    CheckpointInfo info;
    if (!checkpoint.empty()) {
        const OptionGroups given = command_options(*job, request, !algorithm.is_none(), !resolution.is_none(), threads, estimator_options);
        info.command = checkpoint_command(scene->choice, algorithm.is_none() ? "" : job->integrator_info().name, given);
        info.writer = PATHLAB_VERSION;
    }
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
    // As the command line: a fresh film, or the checkpoint resumed (of this render, within its
    // passes); the checkpoints are written every checkpoint_every seconds, at the end, and when
    // Ctrl-C stops the render.
    Film film;
    RenderStats stats;
    run_interruptibly(*job, [&] {
        const Scene& built = job->scene();
        const int width = job->settings.width > 0 ? job->settings.width : built.default_width();
        const int height = job->settings.height > 0 ? job->settings.height : built.default_height();
        if (!checkpoint.empty() || !resume.empty()) info.identity = render_identity(*job, width, height);
        if (resume.empty()) {
            film = make_film(width, height);
        } else {
            ResumedRender resumed = resume_checkpoint(resume, *job, info.identity);
            film = std::move(resumed.film);
            job->settings.done = resumed.done;
            info.seconds = resumed.seconds;
        }
        if (!checkpoint.empty()) {
            info.width = width, info.height = height;
            checkpoint_job(*job, checkpoint, info, job->scene_choice().name);
        }
        stats = job->run_into(film);
    });
    if (const std::string why = final_checkpoint_failure(checkpoint, stats); !why.empty()) {
        PyErr_SetString(PyExc_OSError, why.c_str());
        throw py::error_already_set();
    }
    if (request.aovs.empty()) return py::make_tuple(to_array(film.mean()), to_array(film.standard_error()));
    // The AOVs as the EXR's layers hold them, one array per name: (height, width, channels), or
    // (height, width) for depth and sample-count.
    py::dict aovs;
    const size_t pixels = film.pixel_count();
    for (const std::string& name : request.aovs) {
        const std::vector<ExrChannel> channels = render_aov_channels({name}, film, job->aov_film());
        const size_t k = channels.size();
        py::array_t<float> a = k == 1 ? py::array_t<float>({film.height(), film.width()})
                                      : py::array_t<float>({size_t(film.height()), size_t(film.width()), k});
        float* out = a.mutable_data();
        for (size_t i = 0; i < pixels; ++i)
            for (size_t c = 0; c < k; ++c) out[i * k + c] = channels[c].values[i];
        aovs[py::str(name)] = a;
    }
    return py::make_tuple(to_array(film.mean()), to_array(film.standard_error()), aovs);
}

// nlohmann::json -> Python objects.
py::object to_python(const nlohmann::json& j) {
    if (j.is_object()) {
        py::dict d;
        for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
        return d;
    }
    if (j.is_array()) {
        py::list l;
        for (const auto& v : j) l.append(to_python(v));
        return l;
    }
    if (j.is_boolean()) return py::bool_(j.get<bool>());
    if (j.is_number_integer()) return py::int_(j.get<long long>());
    if (j.is_number()) return py::float_(j.get<double>());
    if (j.is_string()) return py::str(j.get<std::string>());
    return py::none();
}

}  // namespace

// ---- differentiable rendering: parameters by name, gradients, the optimisation loop ----------

// A parameter's value as an array: (1,) for a float, (3,) for an rgb, (height, width, 3) texels.
py::array_t<float> parameter_array(const SceneParameter& p, const std::vector<float>& v) {
    std::vector<py::ssize_t> shape = {py::ssize_t(v.size())};
    if (p.is_texels()) shape = {py::ssize_t(p.height), py::ssize_t(p.width), 3};
    py::array_t<float> a(shape);
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}

py::array_t<float> gradient_array(const SceneParameter& p, const std::vector<double>& g, int offset) {
    std::vector<float> v(size_t(p.size));
    for (int k = 0; k < p.size; ++k) v[size_t(k)] = float(g[size_t(offset + k)]);
    return parameter_array(p, v);
}

// A value for parameter p from a number, a sequence or an array: p.size floats, or (as the
// command line's --set) one number for every component, one colour for every texel. It must be
// finite and within the parameter's range (not clamped: another value would render another scene).
std::vector<float> parameter_from(const SceneParameter& p, const py::object& value) {
    py::array_t<float, py::array::c_style | py::array::forcecast> a;
    try {
        a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
    } catch (const py::error_already_set&) {
        a = {};
    }
    if (!a || py::isinstance<py::str>(value))
        throw py::type_error(fmt::format("{}: the value must be a number, a sequence or an array of numbers", p.name));
    std::vector<float> v(a.data(), a.data() + a.size());
    if (v.size() == 1 && p.size >= 3) v.assign(3, v[0]);
    if (p.is_texels() && v.size() == 3)
        for (int k = 1; k < p.width * p.height; ++k) v.insert(v.end(), {v[0], v[1], v[2]});
    if (int(v.size()) != p.size)
        throw py::value_error(fmt::format("{} takes {} values{}, not {}", p.name, p.size,
                                          p.is_texels() ? fmt::format(" ({}x{}x3; or one value or one colour for every texel)", p.height, p.width) : "",
                                          v.size()));
    std::vector<float> clamped = v;
    clamp_parameter_value(p, clamped);
    for (size_t k = 0; k < v.size(); ++k)
        if (!std::isfinite(v[k]) || clamped[k] != v[k])
            throw py::value_error(fmt::format("{}: {} is outside its range {}", p.name, v[k], p.range()));
    return v;
}

std::vector<std::string> name_list(const py::object& names) {
    if (py::isinstance<py::str>(names)) return {names.cast<std::string>()};
    std::vector<std::string> out;
    for (const py::handle& n : names) {
        if (!py::isinstance<py::str>(n)) throw py::type_error("parameters must be a name (str) or a list of names");
        out.push_back(n.cast<std::string>());
    }
    if (out.empty()) throw py::value_error("parameters: give at least one name (pathlab.params(scene) lists them)");
    return out;
}

DiffSettings diff_settings(int width, int height, const py::object& spp, const py::object& seed, const py::object& max_depth,
                           const py::object& rr_depth) {
    DiffSettings s;
    s.width = width, s.height = height;
    s.spp = *int_argument<int>(spp, "spp", 1, std::numeric_limits<int>::max());
    s.seed = *int_argument<uint64_t>(seed, "seed", 0, std::numeric_limits<uint64_t>::max());
    s.max_depth = int_argument<int>(max_depth, "max_depth", -1, std::numeric_limits<int>::max()).value_or(-1);
    if (s.max_depth == 0) throw py::value_error("max_depth must be positive, or -1 for unlimited");
    s.rr_depth = int_argument<int>(rr_depth, "rr_depth", 0, std::numeric_limits<int>::max()).value_or(3);
    return s;
}

py::dict py_params(const py::object& scene_obj) {
    const std::shared_ptr<PyScene> scene = scene_argument(scene_obj);
    py::dict out;
    for (const SceneParameter& p : scene_parameters(scene->choice.description))
        out[py::str(p.name)] = parameter_array(p, parameter_value(scene->choice.description, p));
    return out;
}

std::shared_ptr<PyScene> py_update(const py::object& scene_obj, const py::dict& values) {
    const std::shared_ptr<PyScene> scene = scene_argument(scene_obj);
    auto out = std::make_shared<PyScene>(PyScene{scene->choice, nullptr});
    out->choice.hash.clear();  // no longer the file's scene
    const std::vector<SceneParameter> all = scene_parameters(out->choice.description);
    for (const auto& [name, value] : values) {
        if (!py::isinstance<py::str>(name)) throw py::type_error("update: the keys are parameter names (str)");
        const SceneParameter& p = find_parameter(all, name.cast<std::string>());
        set_parameter_value(out->choice.description, p, parameter_from(p, py::reinterpret_borrow<py::object>(value)));
    }
    return out;
}

py::tuple py_loss(const py::object& image, const py::object& target, const std::string& kind) {
    const Image a = to_image(image, "image"), t = to_image(target, "target");
    if (a.width() != t.width() || a.height() != t.height())
        throw py::value_error(fmt::format("image is {}x{} but target {}x{}", a.width(), a.height(), t.width(), t.height()));
    Loss loss;
    loss.kind = parse_loss_kind(kind);
    return py::make_tuple(loss_value(a, t, loss), to_array(loss_adjoint(a, t, loss)));
}

py::dict py_gradient(const py::object& scene_obj, const py::object& names, const py::object& adjoint_obj, const py::object& spp,
                     const py::object& seed, const py::object& max_depth, const py::object& rr_depth, const py::object& threads_arg) {
    const std::shared_ptr<PyScene> scene = scene_argument(scene_obj);
    const ParameterSet set = ParameterSet::choose(scene->choice.description, name_list(names));
    const Image adjoint = to_image(adjoint_obj, "adjoint");
    const DiffSettings s = diff_settings(adjoint.width(), adjoint.height(), spp, seed, max_depth, rr_depth);
    const int threads = *int_argument<int>(threads_arg, "threads", 0, std::numeric_limits<int>::max());
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const std::unique_ptr<Scene> built = Scene::build(scene->choice.description);
    std::vector<double> g;
    {
        py::gil_scoped_release release;
        g = gradient(*built, set, s, adjoint);
    }
    py::dict out;
    for (size_t i = 0; i < set.params.size(); ++i) out[py::str(set.params[i].name)] = gradient_array(set.params[i], g, set.offsets[i]);
    return out;
}

py::dict py_optimize(const py::object& scene_obj, const py::object& target_obj, const py::object& names, const py::object& iterations,
                     double lr, const std::string& optimizer, const std::string& loss, const py::object& spp, const py::object& seed,
                     bool seed_per_iteration, const py::object& max_depth, const py::object& rr_depth, const py::object& threads_arg) {
    const std::shared_ptr<PyScene> scene = scene_argument(scene_obj);
    const ParameterSet set = ParameterSet::choose(scene->choice.description, name_list(names));
    const Image target = to_image(target_obj, "target");
    OptimizationSettings s;
    s.render = diff_settings(target.width(), target.height(), spp, seed, max_depth, rr_depth);
    s.loss.kind = parse_loss_kind(loss);
    s.optimizer = parse_optimizer_kind(optimizer);
    if (!(lr > 0) || !std::isfinite(lr)) throw py::value_error("lr must be a positive number");
    s.learning_rate = lr;
    s.iterations = *int_argument<int>(iterations, "iterations", 0, std::numeric_limits<int>::max());
    s.seed_per_iteration = seed_per_iteration;
    const int threads = *int_argument<int>(threads_arg, "threads", 0, std::numeric_limits<int>::max());
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
    py::list losses;
    // Between iterations Python runs its signal handlers: Ctrl-C stops the loop and is raised.
    const OptimizationResult r = optimize(scene->choice.description, set, target, s, [&](const OptimizationStep& step) {
        losses.append(step.loss);
        return PyErr_CheckSignals() == 0;
    });
    if (r.stopped) throw py::error_already_set();
    py::dict params;
    for (size_t i = 0; i < set.params.size(); ++i) {
        const std::vector<float> v(r.theta.begin() + set.offsets[i], r.theta.begin() + set.offsets[i] + set.params[i].size);
        params[py::str(set.params[i].name)] = parameter_array(set.params[i], v);
    }
    py::dict out;
    out["params"] = params;
    out["loss"] = losses;
    out["best_loss"] = r.best_loss;
    return out;
}

PYBIND11_MODULE(pathlab, m) {
    // Images come and go as NumPy arrays: without NumPy, say so at import, naming this
    // interpreter (a python3 first on PATH, pyenv's or a virtualenv's, often lacks it), not at
    // the first render as "No module named 'numpy'".
    try {
        py::module_::import("numpy");
    } catch (py::error_already_set& e) {
        const py::module_ sys = py::module_::import("sys");
        const std::string exe = py::str(sys.attr("executable")), version = py::str(sys.attr("version")).cast<std::string>().substr(0, 6);
        throw py::import_error(fmt::format(
            "pathlab needs NumPy, which this Python ({}, {}) cannot import ({}): install it for this interpreter ({} -m pip install "
            "numpy), or use /usr/bin/python3 with Debian's python3-numpy (scripts/install-deps.sh installs it)",
            exe, version, e.what(), exe));
    }
    m.doc() = "pathlab: a physically based Monte Carlo renderer and light-transport laboratory (see README, Python)";
    m.attr("__version__") = PATHLAB_VERSION;

    py::class_<PyScene, std::shared_ptr<PyScene>>(m, "Scene", "A built-in scene or a scene file, loaded by pathlab.load()")
        .def_property_readonly("name", [](const PyScene& s) { return s.choice.name; })
        .def_property_readonly("index", [](const PyScene& s) -> py::object { return s.choice.builtin ? py::object(py::int_(*s.choice.builtin)) : py::object(py::none()); },
                               "The course index of a built-in scene, else None")
        .def_property_readonly("file", [](const PyScene& s) -> py::object { return s.choice.file.empty() ? py::object(py::none()) : py::object(py::str(s.choice.file)); })
        .def_property_readonly("resolution", [](const PyScene& s) { return py::make_tuple(s.choice.description.width, s.choice.description.height); },
                               "(width, height)")
        .def_property_readonly("parameters", [](const PyScene& s) { return s.choice.parameters; },
                               "A scene file's $name parameters and the values they took")
        .def_property_readonly("hash", [](const PyScene& s) { return s.choice.hash; }, "A scene file's identity (as in reference manifests)")
        .def("__repr__", [](const PyScene& s) {
            return s.choice.builtin ? fmt::format("<pathlab.Scene {} {}>", *s.choice.builtin, s.choice.name)
                                    : fmt::format("<pathlab.Scene {}>", s.choice.file);
        });

    m.def("scenes", [] {
        std::vector<std::string> names;
        for (const BuiltinSceneInfo& b : builtin_scenes()) names.push_back(b.name);
        return names;
    }, "The built-in (course) scenes' names, by course index");
    m.def("algorithms", [] {
        std::vector<std::string> names;
        for (const IntegratorInfo& e : integrators()) names.push_back(e.name);
        return names;
    }, "The estimators' names (the values of algorithm=)");
    m.def("load", &py_load, py::arg("scene"), py::arg("defines") = std::map<std::string, std::string>{},
          "A built-in scene (course index, name or acronym) or a scene file, with values for its $name parameters");
    m.def("render", &py_render, py::arg("scene"), py::arg("algorithm") = py::none(), py::arg("spp") = py::none(), py::arg("seed") = py::int_(1234),
          py::arg("threads") = py::int_(0), py::kw_only(), py::arg("time") = 0.0, py::arg("resolution") = py::none(), py::arg("max_depth") = py::none(),
          py::arg("sampler") = "independent", py::arg("spectral") = false, py::arg("rr_depth") = py::none(),
          py::arg("light_sampler") = py::none(), py::arg("ris_candidates") = py::none(), py::arg("light_split") = py::none(), py::arg("first_sample") = py::int_(0),
          py::arg("checkpoint") = py::none(), py::arg("checkpoint_every") = kDefaultCheckpointEvery, py::arg("resume") = py::none(),
          py::arg("aovs") = py::none(),
          "Renders a scene (a pathlab.Scene, or what load() takes) and returns (image, standard_error), float32 arrays of shape\n"
          "(height, width, 3). As the command line: algorithm defaults to the scene file's integrator, else pt-mis; spp to the\n"
          "scene file's sample count, else 64 (unlimited with time=seconds); seed to 1234; threads=0 uses all cores. The same\n"
          "settings give the same bytes as `pathlab SCENE -a ALGORITHM --spp N --seed S -o out.exr`; spectral, rr_depth,\n"
          "light_sampler ('uniform', 'power', 'bvh', 'ris'), ris_candidates and light_split are --spectral, --rr-depth,\n"
          "--light-sampler, --ris-candidates and --light-split. The estimators' own options go by their command-line names: mis='power', photons, radius, alpha,\n"
          "volume_estimate='points', no_merging=True, no_connections=True, ic_rays, ic_error, ic_no_gradients=True, pbgi_surfels,\n"
          "pbgi_cutoff, pbgi_bounces, pbgi_resolution, pbgi_direct_samples, pbgi_spacing, guiding_spp, guiding_rr=True, guiding_fraction (0.5 or 'learned'), guiding ('sd-tree' or 'vmm'), estimators, photon_beams, beam_radius (refused for another estimator),\n"
          "null_depth='skip' (--null-depth).\n"
          "first_sample is --first-sample: the index of the first sample (pass), so that renders of disjoint ranges add up, with\n"
          "`pathlab merge`, to one render (give them checkpoint= files: merge takes checkpoints, exactly). checkpoint=FILE saves\n"
          "the render's whole state every checkpoint_every seconds (default 300; 0: only at the end), at the end and on Ctrl-C;\n"
          "resume=FILE continues such a checkpoint (the same scene and settings; spp may be raised) and goes on checkpointing\n"
          "to it. The files are the command line's: `pathlab --resume FILE` continues a checkpoint written here, and resume=\n"
          "one the command line wrote, to the bytes of the render never interrupted. aovs=['albedo', 'normal', 'depth', 'position',\n"
          "'variance', 'sample-count'] (or a comma-separated string) is --aovs: the result is then (image, standard_error, aovs),\n"
          "aovs a dict of arrays, (height, width, 3) or (height, width) for depth and sample-count.");
    m.def("compare", [](const py::object& a, const py::object& b) {
        const Image ia = to_image(a, "a"), ib = to_image(b, "b");
        if (ia.width() != ib.width() || ia.height() != ib.height())
            throw py::value_error(fmt::format("a is {}x{} but b is {}x{}: images of different sizes cannot be compared", ia.width(), ia.height(),
                                              ib.width(), ib.height()));
        return to_python(image_difference_json(compare_images(ia, ib)));
    }, py::arg("a"), py::arg("b"),
          "The statistics of a - b (b the reference), as `pathlab compare A B --json` prints them: per channel and over all, the mean\n"
          "difference, MAE, RMSE, relMSE and largest difference, and the NaN/Inf counts. a and b are arrays or image files.");
    m.def("rmse", [](const py::object& img, const py::object& reference, const py::object& reference_se) {
        const Image a = to_image(img, "image"), r = to_image(reference, "reference");
        const Image se = reference_se.is_none() ? Image() : to_image(reference_se, "reference_se");
        if (a.width() != r.width() || a.height() != r.height()) throw py::value_error("image and reference differ in size");
        if (!reference_se.is_none() && (se.width() != r.width() || se.height() != r.height()))
            throw py::value_error(fmt::format("reference_se is {}x{} but the reference {}x{}", se.width(), se.height(), r.width(), r.height()));
        return rmse_against_reference(a, r, se);
    }, py::arg("image"), py::arg("reference"), py::arg("reference_se") = py::none(),
          "RMSE against a reference with the reference's own noise (its standard errors, if given) removed, as pathlab report computes it");
    m.def("write", [](const std::string& path, const py::object& img, float exposure) {
        const Image image = to_image(img, "image");
        translating([&] {
            write_image(image, path, exposure);
            return 0;
        });
    }, py::arg("path"), py::arg("image"), py::arg("exposure") = 0.0f,
          "Writes an (H, W, 3) array; the format follows the extension: .exr, .hdr, .pfm, .png (sRGB, with exposure in stops)");
    m.def("read", [](const std::string& path) { return to_array(translating([&] { return read_image(path); })); }, py::arg("path"),
          "Reads a linear image (.exr, .hdr, .pfm) as a float32 array of shape (height, width, 3)");
    m.def("params", &py_params, py::arg("scene"),
          "The scene's differentiable parameters, as `pathlab params` lists them (Mitsuba 3's names): a dict of name to value, a\n"
          "float32 array of shape (1,) for a float, (3,) for an rgb, (height, width, 3) for a bitmap's texels");
    m.def("update", &py_update, py::arg("scene"), py::arg("values"),
          "A copy of the scene with parameters set: values is a dict of name to a number, a sequence or an array (one number for\n"
          "every component, or one colour for every texel, as --set). A value outside the parameter's range is a ValueError. The\n"
          "copy's hash is empty: it is no longer the file's scene.");
    m.def("loss", &py_loss, py::arg("image"), py::arg("target"), py::arg("kind") = "l2",
          "(loss, adjoint): the mean over pixels and channels of (image - target)^2 ('l2') or |image - target| ('l1'), and its\n"
          "derivative with respect to each pixel, the adjoint image gradient() takes");
    m.def("gradient", &py_gradient, py::arg("scene"), py::arg("parameters"), py::arg("adjoint"), py::kw_only(), py::arg("spp") = py::int_(4),
          py::arg("seed") = py::int_(1234), py::arg("max_depth") = py::none(), py::arg("rr_depth") = py::none(), py::arg("threads") = py::int_(0),
          "dLoss/dtheta by path replay for the named parameters, where adjoint (height, width, 3) is dLoss/dImage of pt-mis's image\n"
          "of that size, volpath's in a scene with media (render(scene, 'pt-mis', spp, seed) gives it; use another seed here, so the\n"
          "gradient is unbiased): a dict of\n"
          "name to an array shaped as the parameter's value. As `pathlab gradient`.");
    m.def("optimize", &py_optimize, py::arg("scene"), py::arg("target"), py::arg("parameters"), py::kw_only(),
          py::arg("iterations") = py::int_(50), py::arg("lr") = 0.02, py::arg("optimizer") = "adam", py::arg("loss") = "l2",
          py::arg("spp") = py::int_(4), py::arg("seed") = py::int_(1234), py::arg("seed_per_iteration") = false,
          py::arg("max_depth") = py::none(), py::arg("rr_depth") = py::none(), py::arg("threads") = py::int_(0),
          "Recovers the named parameters from a target image (array or file; its size is the render's) by gradient descent, as\n"
          "`pathlab optimize`: returns {'params': name -> value after the last step, 'loss': per iteration, 'best_loss'}.\n"
          "pathlab.update(scene, result['params']) gives the optimised scene. A medium's sigma_t is always optimised with new\n"
          "random numbers every iteration (seed_per_iteration), as on the command line.");
}
