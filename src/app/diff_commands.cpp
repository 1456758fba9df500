#include "app/diff_commands.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include <tbb/global_control.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/command_arguments.hpp"
#include "app/interrupt.hpp"
#include "diff/loss.hpp"
#include "diff/optimization.hpp"
#include "diff/optimizer.hpp"
#include "diff/path_replay.hpp"
#include "diff/scene_file_update.hpp"
#include "image/image_io.hpp"
#include "job/scene_choice.hpp"
#include "job/usage_error.hpp"
#include "judge/false_colour.hpp"
#include "judge/svg_plot.hpp"
#include "scene/medium_in_use.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab {
namespace {

SceneChoice one_scene(const std::string& spec, const std::vector<std::string>& defines) {
    std::vector<SceneChoice> scenes = resolve_scenes(spec, parse_defines(defines));
    if (scenes.size() != 1) throw UsageError(fmt::format("give one scene, not '{}'", spec));
    return std::move(scenes.front());
}

std::string value_text(const std::vector<float>& v) {
    return v.size() == 1 ? fmt::format("{:.6g}", v[0]) : fmt::format("{:.6g}, {:.6g}, {:.6g}", v[0], v[1], v[2]);
}

// The mean of an rgb parameter's components per channel (of texels: over the texels).
std::vector<float> channel_means(const std::vector<float>& v) {
    if (v.size() <= 3) return v;
    double m[3] = {0, 0, 0};
    for (size_t i = 0; i < v.size(); ++i) m[i % 3] += v[i];
    const double n = double(v.size() / 3);
    return {float(m[0] / n), float(m[1] / n), float(m[2] / n)};
}

// A parameter's value in a line: texels as their size and mean colour.
std::string value_text(const SceneParameter& p, const std::vector<float>& v) {
    if (!p.is_texels()) return value_text(v);
    return fmt::format("{}x{} texels, mean {:.4g}, {:.4g}, {:.4g}", p.width, p.height, channel_means(v)[0], channel_means(v)[1],
                       channel_means(v)[2]);
}

// The texels of a parameter as an image (linear values).
Image texel_image(const SceneParameter& p, const std::vector<float>& v) {
    Image img(p.width, p.height);
    for (size_t i = 0; i < img.pixel_count(); ++i) img[i] = Rgb(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    return img;
}

// `name.data[k]`: texel k (row-major, top row first) of a texture; k = -1 for other names.
std::pair<std::string, long> split_texel_index(const std::string& name) {
    const size_t open = name.rfind('[');
    if (open == std::string::npos || name.back() != ']') return {name, -1};
    const std::string digits = name.substr(open + 1, name.size() - open - 2);
    char* end = nullptr;
    const long k = std::strtol(digits.c_str(), &end, 10);
    if (digits.empty() || *end || k < 0) throw UsageError(fmt::format("'{}': the texel index in [] must be a non-negative whole number", name));
    return {name.substr(0, open), k};
}

template <typename F>
auto usage_on_invalid(F&& f) {
    try {
        return f();
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
}

uint64_t parse_seed(const std::string& text) {
    char* end = nullptr;
    const uint64_t s = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || *end) throw UsageError(fmt::format("--seed: '{}' is not a non-negative integer", text));
    return s;
}

// The chosen parameters, with --set start values applied (and clamped) to the description.
// What gradient's forward mode was asked for: a parameter of the set, and one of its texels
// (`name.data[k]`) or -1 for all of it.
struct ForwardItem {
    size_t param;
    long texel;
};

// `items` (gradient only): the names as given, several texels of one texture allowed.
ParameterSet choose_parameters(SceneDescription& d, const DiffCommonOptions& o, std::vector<ForwardItem>* items = nullptr) {
    std::vector<std::string> names = split_comma_list(o.params);
    if (o.params.empty()) throw UsageError("--params: give at least one parameter (`pathlab params SCENE` lists them)");
    std::vector<std::pair<std::string, long>> asked;
    if (items) {
        // The set takes each texture once, whichever of its texels are named.
        std::vector<std::string> unique;
        for (const std::string& n : names) {
            const auto item = split_texel_index(n);
            if (std::find(asked.begin(), asked.end(), item) != asked.end()) throw UsageError(fmt::format("parameter '{}' is given twice", n));
            asked.push_back(item);
            if (std::find(unique.begin(), unique.end(), item.first) == unique.end()) unique.push_back(item.first);
        }
        names = unique;
    }
    const ParameterSet set = usage_on_invalid([&] { return ParameterSet::choose(d, names); });
    if (items) {
        items->clear();
        for (const auto& [name, k] : asked) {
            const size_t i = size_t(std::find(names.begin(), names.end(), name) - names.begin());
            const SceneParameter& p = set.params[i];
            if (k >= 0 && !p.is_texels()) throw UsageError(fmt::format("{}: only a texture's texels (.data) take an index", p.name));
            if (k >= long(p.width) * p.height)
                throw UsageError(fmt::format("{}[{}]: the texture has {}x{} = {} texels", p.name, k, p.width, p.height, p.width * p.height));
            items->push_back({i, k});
        }
    }
    const std::vector<SceneParameter> all = scene_parameters(d);
    for (const std::string& item : o.initial) {
        const size_t eq = item.find('=');
        if (eq == std::string::npos) throw UsageError(fmt::format("--set '{}': expected name=value or name=r,g,b", item));
        const SceneParameter& p = usage_on_invalid([&]() -> const SceneParameter& { return find_parameter(all, item.substr(0, eq)); });
        std::vector<float> v;
        for (const std::string& x : split_comma_list(item.substr(eq + 1))) {
            char* end = nullptr;
            const float f = std::strtof(x.c_str(), &end);
            if (x.empty() || *end || !std::isfinite(f)) throw UsageError(fmt::format("--set '{}': '{}' is not a number", item, x));
            v.push_back(f);
        }
        if (v.size() == 1 && p.size >= 3) v.assign(3, v[0]);
        if (p.is_texels() && v.size() == 3)  // one colour for every texel
            for (int k = 1; k < p.width * p.height; ++k) v.insert(v.end(), {v[0], v[1], v[2]});
        if (int(v.size()) != p.size)
            throw UsageError(fmt::format("--set '{}': {} takes {} values{}", item, p.name, p.size,
                                         p.is_texels() ? " (or one value or one colour for every texel)" : ""));
        clamp_parameter_value(p, v);
        set_parameter_value(d, p, v);
    }
    return set;
}

DiffSettings settings_of(const DiffCommonOptions& o, int width, int height) {
    DiffSettings s;
    s.width = width, s.height = height;
    s.seed = parse_seed(o.seed);
    if (o.spp < 1) throw UsageError("--spp must be at least 1");
    s.spp = o.spp;
    s.max_depth = o.max_depth;
    s.rr_depth = o.rr_depth;
    return s;
}

void add_common_options(CLI::App* cmd, DiffCommonOptions& o) {
    cmd->add_option("--scene", o.scene, "Scene: a built-in course scene (index or name) or a scene file")->required();
    cmd->add_option("--params", o.params, "Comma-separated parameter names (`pathlab params SCENE` lists them)")->required();
    cmd->add_option("--set", o.initial, "Start value of a parameter: name=v or name=r,g,b (repeatable)");
    cmd->add_option("--spp", o.spp, "Samples per pixel of each evaluation")->capture_default_str();
    cmd->add_option("--seed", o.seed, "Random seed")->capture_default_str();
    cmd->add_option("--max-depth", o.max_depth, "Longest path in bounces (-1: unlimited)")->capture_default_str();
    cmd->add_option("--rr-depth", o.rr_depth, "Bounces before Russian roulette (-1: never)")->capture_default_str();
    cmd->add_option("--resolution", o.resolution, "WIDTHxHEIGHT of the renders");
    cmd->add_option("-D,--define", o.defines, "name=value for $name in the scene file (repeatable; overrides <default>)");
    add_threads_option(*cmd, o.threads);
}

Image read_target(const std::string& path) {
    try {
        return read_image(path);
    } catch (const ImageIoError& e) {
        throw UsageError(e.what());
    }
}

void write_json(const std::string& path, const nlohmann::json& j) { write_text_file(path, j.dump(2) + "\n"); }

std::vector<float> slice(const ParameterSet& set, size_t i, const std::vector<float>& theta) {
    return std::vector<float>(theta.begin() + set.offsets[i], theta.begin() + set.offsets[i] + set.params[i].size);
}

// The parameters by name; texels in full, or (`compact`, per iteration) as their mean colour.
nlohmann::json parameters_json(const ParameterSet& set, const std::vector<float>& theta, bool compact = false) {
    nlohmann::json j = nlohmann::json::object();
    for (size_t i = 0; i < set.params.size(); ++i) {
        const std::vector<float> v = slice(set, i, theta);
        j[set.params[i].name] = compact && set.params[i].is_texels() ? nlohmann::json{{"mean", channel_means(v)}} : nlohmann::json(v);
    }
    return j;
}

// The gradient: in full, or (with texels) by name, texels as the gradient's norm.
nlohmann::json gradient_json(const ParameterSet& set, const std::vector<double>& g) {
    bool texels = false;
    for (const SceneParameter& p : set.params) texels = texels || p.is_texels();
    if (!texels) return g;
    nlohmann::json j = nlohmann::json::object();
    for (size_t i = 0; i < set.params.size(); ++i) {
        const std::vector<double> gi(g.begin() + set.offsets[i], g.begin() + set.offsets[i] + set.params[i].size);
        if (!set.params[i].is_texels()) {
            j[set.params[i].name] = gi;
            continue;
        }
        double n2 = 0;
        for (double x : gi) n2 += x * x;
        j[set.params[i].name] = {{"norm", std::sqrt(n2)}};
    }
    return j;
}

// gradient and optimize write images, scene.xml, textures and JSON under fixed names in --out:
// a folder that holds a file they read (the scene file, a texture or mesh it reads, the target)
// is refused, since one of those names may be that file (optimize's scene.xml over the scene).
void refuse_out_dir_with_inputs(const std::string& out_dir, const SceneChoice& scene, const std::string& target, const char* command) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path dir = fs::weakly_canonical(fs::absolute(out_dir), ec);
    if (ec) return;
    std::vector<std::string> inputs = scene.files;
    if (!target.empty()) inputs.push_back(target);
    for (const std::string& in : inputs) {
        const fs::path p = fs::weakly_canonical(fs::absolute(in), ec);
        if (ec) continue;
        if (p.parent_path() == dir)
            throw UsageError(fmt::format("--out {} holds {}, which {} reads: its outputs there could replace it; choose another folder",
                                         out_dir, in, command));
    }
}

}  // namespace

// ---- params ------------------------------------------------------------------------------

CLI::App* add_params_command(CLI::App& app, ParamsOptions& o) {
    CLI::App* cmd = app.add_subcommand("params", "List a scene's differentiable parameters: name, kind, value, size (docs/differentiable.md)");
    cmd->add_option("SCENE", o.scene, "A built-in course scene (index or name) or a scene file")->required();
    cmd->add_flag("--json", o.json, "Print them as JSON");
    cmd->add_option("-D,--define", o.defines, "name=value for $name in the scene file (repeatable; overrides <default>)");
    return cmd;
}

int run_params_command(const ParamsOptions& o) {
    const SceneChoice scene = one_scene(o.scene, o.defines);
    const std::vector<SceneParameter> params = scene_parameters(scene.description);
    if (o.json) {
        nlohmann::json j = nlohmann::json::array();
        for (const SceneParameter& p : params)
        {
            nlohmann::json e = {{"name", p.name}, {"kind", p.kind()}, {"value", parameter_value(scene.description, p)}, {"size", p.size},
                                {"range", p.range()}};
            if (p.is_texels()) e["shape"] = {p.height, p.width, 3};  // as Mitsuba 3's TensorXf: rows, columns, channels
            j.push_back(e);
        }
        fmt::print("{}\n", j.dump(2));
        return 0;
    }
    size_t width = 4;
    for (const SceneParameter& p : params) width = std::max(width, p.name.size());
    fmt::print("{:<{}}  {:<7}  {:<34}  {:>4}  {}\n", "name", width, "kind", "value", "size", "range");
    for (const SceneParameter& p : params)
        fmt::print("{:<{}}  {:<7}  {:<34}  {:>4}  {}\n", p.name, width, p.kind(), value_text(p, parameter_value(scene.description, p)),
                   p.size, p.range());
    if (params.empty()) fmt::print("(none: differentiable parameters need ids on the scene's <bsdf>, <shape>, <emitter> and <medium> elements)\n");
    if (const std::string medium = medium_in_use(scene.description); !medium.empty())
        fmt::print("(this scene has the {}: gradient and optimize differentiate volpath's estimator)\n", medium);
    return 0;
}

// ---- gradient ----------------------------------------------------------------------------

CLI::App* add_gradient_command(CLI::App& app, GradientOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "gradient", "Forward-mode images dI/dtheta (one per parameter) and the reverse-mode gradient of a loss (path replay)");
    add_common_options(cmd, o.common);
    cmd->add_option("--target", o.target, "Target image: the gradient is of the L2 loss against it (default: of the mean pixel value)");
    cmd->add_option("--out", o.out_dir, "Folder for the images")->capture_default_str();
    return cmd;
}

int run_gradient_command(const GradientOptions& o) {
    std::optional<tbb::global_control> threads;
    limit_threads(threads, o.common.threads);
    SceneChoice scene = one_scene(o.common.scene, o.common.defines);
    std::vector<ForwardItem> items;
    const ParameterSet set = choose_parameters(scene.description, o.common, &items);
    int w = 64, h = 64;
    Image target;
    if (!o.target.empty()) {
        target = read_target(o.target);
        w = target.width(), h = target.height();
    }
    if (!o.common.resolution.empty()) parse_resolution_option(o.common.resolution, w, h);
    const DiffSettings s = settings_of(o.common, w, h);
    refuse_out_dir_with_inputs(o.out_dir, scene, o.target, "gradient");
    const std::unique_ptr<Scene> built = Scene::build(scene.description);
    std::filesystem::create_directories(o.out_dir);
    const Image primal = render_primal(*built, s);
    write_image(primal, o.out_dir + "/primal.exr");
    write_image(primal, o.out_dir + "/primal.png");
    Image adjoint(w, h, Rgb(1.0f / (3.0f * float(w) * float(h))));  // the mean pixel value's
    if (target.pixel_count() > 0) adjoint = loss_adjoint(primal, target, Loss{});
    DiffSettings gs = s;
    gs.seed = s.seed + 1;  // independent of the primal image that made the adjoint
    const std::vector<double> g = gradient(*built, set, gs, adjoint);
    for (const auto& [i, texel] : items) {
        const SceneParameter& p = set.params[i];
        // A texel named by index: the tangent moves its three channels; a whole texture: all texels.
        std::vector<float> t = parameter_tangent(set, i);
        std::string name = p.name;
        if (texel >= 0) {
            std::fill(t.begin(), t.end(), 0.0f);
            for (int c = 0; c < 3; ++c) t[size_t(set.offsets[i] + 3 * texel + c)] = 1;
            name += fmt::format("[{}]", texel);
        }
        const Image d = forward_gradient(*built, set, s, t);
        const std::string base = o.out_dir + "/d_" + name;
        write_image(d, base + ".exr");
        const Image zero(d.width(), d.height());
        write_png8(false_colour_difference(d, zero, difference_scale(d, zero)), base + ".png");
        std::vector<double> gi(g.begin() + set.offsets[i], g.begin() + set.offsets[i] + p.size);
        if (texel >= 0) gi = std::vector<double>(gi.begin() + 3 * texel, gi.begin() + 3 * texel + 3);
        if (p.is_texels() && texel < 0) {
            // Texels: the gradient as an image beside the forward one (written, not printed).
            Image gimg(p.width, p.height);
            for (size_t k = 0; k < gimg.pixel_count(); ++k) gimg[k] = Rgb(float(gi[3 * k]), float(gi[3 * k + 1]), float(gi[3 * k + 2]));
            write_image(gimg, o.out_dir + "/grad_" + name + ".exr");
            fmt::print("{}: dLoss/dtheta per texel in {}/grad_{}.exr; forward image (all texels moved) {}.exr\n", name, o.out_dir, name, base);
            continue;
        }
        fmt::print("{}: dLoss/dtheta = [{:.6g}]; forward image {}.exr\n", name, fmt::join(gi, ", "), base);
    }
    return 0;
}

// ---- optimize ----------------------------------------------------------------------------

CLI::App* add_optimize_command(CLI::App& app, OptimizeOptions& o) {
    CLI::App* cmd = app.add_subcommand("optimize", "Recover scene parameters from a target image by gradient descent (path replay gradients)");
    add_common_options(cmd, o.common);
    cmd->add_option("--target", o.target, "Target image (.exr, .hdr, .pfm): its size is the render's")->required();
    cmd->add_option("--iterations", o.iterations, "Gradient steps")->capture_default_str();
    cmd->add_option("--lr", o.lr, "Learning rate")->capture_default_str();
    cmd->add_option("--optimizer", o.optimizer, "adam or gd (plain gradient descent)")->capture_default_str();
    cmd->add_option("--loss", o.loss, "l2 or l1 (mean over pixels and channels)")->capture_default_str();
    cmd->add_option("--region", o.region, "x0,y0,x1,y1: the loss over this pixel region only");
    cmd->add_flag("--seed-per-iteration", o.seed_per_iteration,
                  "New random numbers every iteration (default: the same ones, but for a medium's sigma_t)");
    cmd->add_option("--save-every", o.save_every, "Write the image every this many iterations (0: never)")->capture_default_str();
    cmd->add_option("--out", o.out_dir, "Folder for loss.json, loss.svg, images, params.json and scene.xml")->capture_default_str();
    cmd->add_flag("-q,--quiet", o.quiet, "No line per iteration");
    return cmd;
}

int run_optimize_command(const OptimizeOptions& o) {
    std::optional<tbb::global_control> threads;
    limit_threads(threads, o.common.threads);
    SceneChoice scene = one_scene(o.common.scene, o.common.defines);
    const ParameterSet set = choose_parameters(scene.description, o.common);
    const Image target = read_target(o.target);
    int w = target.width(), h = target.height();
    if (!o.common.resolution.empty()) parse_resolution_option(o.common.resolution, w, h);
    if (w != target.width() || h != target.height())
        throw UsageError(fmt::format("--resolution {}x{} differs from the target's {}x{}", w, h, target.width(), target.height()));
    const DiffSettings base = settings_of(o.common, w, h);
    Loss loss;
    loss.kind = usage_on_invalid([&] { return parse_loss_kind(o.loss); });
    if (!o.region.empty()) {
        const std::vector<std::string> r = split_comma_list(o.region);
        int v[4];
        for (size_t i = 0; i < 4 && r.size() == 4; ++i) {
            char* end = nullptr;
            v[i] = int(std::strtol(r[i].c_str(), &end, 10));
            if (r[i].empty() || *end) throw UsageError(fmt::format("--region '{}': '{}' is not a whole number", o.region, r[i]));
        }
        if (r.size() != 4) throw UsageError(fmt::format("--region '{}': expected x0,y0,x1,y1 (pixels)", o.region));
        loss.x0 = v[0], loss.y0 = v[1], loss.x1 = v[2], loss.y1 = v[3];
        usage_on_invalid([&] { return loss_value(target, target, loss); });
    }
    OptimizationSettings settings;
    settings.render = base;
    settings.loss = loss;
    settings.optimizer = usage_on_invalid([&] { return parse_optimizer_kind(o.optimizer); });
    settings.learning_rate = o.lr;
    settings.iterations = o.iterations;
    settings.seed_per_iteration = o.seed_per_iteration;
    if (const SceneParameter* e = extinction_parameter(set); e && !o.seed_per_iteration && !o.quiet)
        fmt::print("({} is optimised with new random numbers every iteration, as with --seed-per-iteration: docs/differentiable.md)\n", e->name);
    if (o.iterations < 0) throw UsageError("--iterations must not be negative");
    if (!(o.lr > 0)) throw UsageError("--lr must be positive");
    refuse_out_dir_with_inputs(o.out_dir, scene, o.target, "optimize");
    std::filesystem::create_directories(o.out_dir);
    check_writable_path(o.out_dir + "/loss.json");

    nlohmann::json history = nlohmann::json::array();
    PlotSeries series{"loss", series_colour(0), {}};
    InterruptGuard guard;
    const auto start = std::chrono::steady_clock::now();
    const OptimizationResult run = optimize(scene.description, set, target, settings, [&](const OptimizationStep& step) {
        const int it = step.iteration;
        history.push_back({{"iteration", it},
                           {"loss", step.loss},
                           {"params", parameters_json(set, step.theta, true)},
                           {"gradient", gradient_json(set, step.gradient)}});
        series.points.push_back({double(it + 1), step.loss});
        if (o.save_every > 0 && it % o.save_every == 0) {
            write_image(step.image, fmt::format("{}/iteration_{:04d}.png", o.out_dir, it));
            for (size_t i = 0; i < set.params.size(); ++i)
                if (set.params[i].is_texels())
                    write_image(texel_image(set.params[i], slice(set, i, step.theta)), fmt::format("{}/{}_{:04d}.png", o.out_dir, set.params[i].name, it));
        }
        if (!o.quiet) {
            std::string values;
            for (size_t i = 0; i < set.params.size(); ++i)
                values += fmt::format("  {}=[{}]", set.params[i].name, value_text(set.params[i], slice(set, i, step.theta)));
            fmt::print("iteration {:4d}  loss {:.6g}{}\n", it, step.loss, values);
        }
        return !InterruptGuard::flag().load();
    });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const bool interrupted = run.stopped;
    // Interrupted: the parameters of the lowest loss seen; otherwise the last step's.
    const std::vector<float>& result = run.theta;
    SceneDescription desc = scene.description;
    set.set_values(desc, result);
    {
        const std::unique_ptr<Scene> built = Scene::build(desc);
        DiffSettings s = base;
        s.seed = base.seed + 7777;  // an independent final image
        const Image final_image = render_primal(*built, s);
        write_image(final_image, o.out_dir + "/final.exr");
        write_image(final_image, o.out_dir + "/final.png");
        const double final_loss = loss_value(final_image, target, loss);
        write_json(o.out_dir + "/params.json", {{"scene", scene.file.empty() ? scene.name : scene.file},
                                                {"params", parameters_json(set, result)},
                                                {"final_loss", final_loss},
                                                {"interrupted", interrupted}});
        write_json(o.out_dir + "/loss.json", {{"scene", scene.file.empty() ? scene.name : scene.file},
                                              {"target", o.target},
                                              {"optimizer", o.optimizer},
                                              {"lr", o.lr},
                                              {"spp", o.common.spp},
                                              {"loss", o.loss},
                                              {"iterations", history},
                                              {"best", {{"loss", run.best_loss}, {"params", parameters_json(set, run.best)}}},
                                              {"final", {{"loss", final_loss}, {"params", parameters_json(set, result)}}},
                                              {"seconds", seconds}});
        LogLogPlot plot{"pathlab optimize: loss per iteration", "iteration", fmt::format("{} loss", o.loss)};
        plot.slope_guide = false;
        write_text_file(o.out_dir + "/loss.svg", log_log_svg(plot, {series}));
        // Texels: an EXR of the linear values (exactly what was optimised) and a PNG to look at.
        std::map<std::string, std::string> texel_files;
        for (size_t i = 0; i < set.params.size(); ++i) {
            if (!set.params[i].is_texels()) continue;
            const Image tex = texel_image(set.params[i], slice(set, i, result));
            write_image(tex, o.out_dir + "/" + set.params[i].name + ".exr");
            write_image(tex, o.out_dir + "/" + set.params[i].name + ".png");
            texel_files[set.params[i].name] = set.params[i].name + ".exr";  // next to scene.xml
        }
        if (!scene.file.empty()) {
            try {
                write_text_file(o.out_dir + "/scene.xml", scene_file_with_values(scene.file, set, result, texel_files, &desc));
            } catch (const std::runtime_error& e) {
                fmt::print(stderr, "pathlab: {}\n", e.what());
            }
        }
        fmt::print("{} iterations in {:.1f} s; final loss {:.6g}{}; written to {}/ (params.json, loss.json, loss.svg, final.exr{})\n", run.iterations,
                   seconds, final_loss, interrupted ? " (interrupted: the best parameters so far)" : "", o.out_dir,
                   scene.file.empty() ? "" : ", scene.xml");
    }
    return interrupted ? interrupted_exit_code() : 0;
}

}  // namespace pathlab
