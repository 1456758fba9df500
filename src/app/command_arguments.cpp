#include "app/command_arguments.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <limits>
#include <optional>
#include <string_view>
#include <thread>

#include <fmt/format.h>

#include "job/usage_error.hpp"

namespace pathlab {

namespace {

// A whole number of decimal digits only (no sign, no exponent, no spaces), within [lo, hi].
std::optional<uint64_t> parse_whole_number(std::string_view text, uint64_t lo, uint64_t hi) {
    if (text.empty() || text.size() > 20) return std::nullopt;
    uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || ptr != text.data() + text.size() || v < lo || v > hi) return std::nullopt;
    return v;
}

}  // namespace

bool parse_resolution(const std::string& text, int& width, int& height) {
    const size_t x = text.find_first_of("xX");
    if (x == std::string::npos) return false;
    const auto w = parse_whole_number(std::string_view(text).substr(0, x), 1, kMaxResolution);
    const auto h = parse_whole_number(std::string_view(text).substr(x + 1), 1, kMaxResolution);
    if (!w || !h) return false;
    width = int(*w), height = int(*h);
    return true;
}

void parse_resolution_option(const std::string& text, int& width, int& height) {
    width = height = 0;
    if (!text.empty() && !parse_resolution(text, width, height))
        throw UsageError(fmt::format("invalid --resolution '{}': expected WxH with whole numbers from 1 to {}, e.g. 512x512",
                                     text, kMaxResolution));
}

uint64_t parse_seed_option(const std::string& text) {
    const auto v = parse_whole_number(text, 0, std::numeric_limits<uint64_t>::max());
    if (!v)
        throw UsageError(fmt::format("invalid --seed '{}': expected a whole number from 0 to {}", text,
                                     std::numeric_limits<uint64_t>::max()));
    return *v;
}

void add_threads_option(CLI::App& app, int& threads) {
    app.add_option("--threads", threads, fmt::format("Worker threads (default: all cores; at most {} x the cores)", kMaxThreadsPerCore));
}

void limit_threads(std::optional<tbb::global_control>& limit, int threads) {
    if (threads != 0) limit.emplace(tbb::global_control::max_allowed_parallelism, thread_count_or_cap(threads));
}

size_t thread_count_or_cap(int requested) {
    if (requested <= 0) throw UsageError(fmt::format("--threads must be positive, got {}", requested));
    const size_t cores = std::max(1u, std::thread::hardware_concurrency());
    const size_t cap = kMaxThreadsPerCore * cores;
    if (size_t(requested) <= cap) return size_t(requested);
    fmt::print(stderr, "pathlab: --threads {} is more than {} x the {} cores: using {}\n", requested, kMaxThreadsPerCore, cores, cap);
    return cap;
}

const char* const kInterruptHelp =
    "Ctrl-C (or SIGTERM): the first stops after the current pass and writes what was rendered, normalised by the samples "
    "taken (exit code 130; 143 for SIGTERM); a second one aborts at once, prints that it aborted and writes no image "
    "(exit code 130; 143 for SIGTERM).\nOutput directories that do not exist are created.";

void add_scene_arguments(CLI::App& app, SceneArguments& a) {
    app.add_option("scene", a.positional,
                   "Scene(s): course index 0-7, name or acronym (see `pathlab scenes`), a scene file (.xml, or glTF: .gltf .glb), 'all', or several "
                   "(also comma-separated)");
    app.add_option("-s,--scene", a.option,
                   "The same as an option: course index, name, scene file (.xml, .gltf, .glb), a comma-separated list, or 'all'");
    app.add_option("-D,--define", a.defines, "name=value for $name in scene files (repeatable; overrides <default>; a name no scene uses is an error)");
}

std::string scene_spec(const SceneArguments& a) {
    if (!a.positional.empty() && !a.option.empty())
        throw UsageError(fmt::format("the scene is given twice ({} and --scene {}): give it once", fmt::join(a.positional, " "), a.option));
    return a.positional.empty() ? a.option : fmt::format("{}", fmt::join(a.positional, ","));
}

SceneDefines parse_defines(const std::vector<std::string>& list) {
    SceneDefines defines;
    for (const std::string& d : list) {
        const size_t eq = d.find('=');
        if (eq == std::string::npos || eq == 0) throw UsageError(fmt::format("invalid -D '{}': expected name=value", d));
        defines[d.substr(0, eq)] = d.substr(eq + 1);
    }
    return defines;
}

std::vector<SceneChoice> resolve_scene_arguments(const SceneArguments& a, const std::string& fallback) {
    const std::string given = scene_spec(a);
    const std::string spec = given.empty() ? fallback : given;
    if (spec.empty())
        throw UsageError("no scene given: pathlab SCENE [options], where SCENE is a course index 0-7, a name (see `pathlab "
                         "scenes`), a scene file (.xml, or glTF: .gltf .glb), a comma-separated list, or 'all'");
    return resolve_scenes(spec, parse_defines(a.defines));
}

PixelRect parse_crop_option(const std::string& text) {
    const std::vector<std::string> items = split_comma_list(text);
    std::vector<uint64_t> v;
    for (const std::string& item : items)
        if (const auto n = parse_whole_number(item, 0, kMaxResolution)) v.push_back(*n);
    if (items.size() != 4 || v.size() != 4 || v[2] == 0 || v[3] == 0)
        throw UsageError(fmt::format("invalid --crop '{}': expected X,Y,W,H in pixels from the top left, e.g. 100,80,64,48", text));
    return {int(v[0]), int(v[1]), int(v[2]), int(v[3])};
}

std::pair<int, int> parse_pixel_option(const std::string& text) {
    const std::vector<std::string> items = split_comma_list(text);
    std::vector<uint64_t> v;
    for (const std::string& item : items)
        if (const auto n = parse_whole_number(item, 0, kMaxResolution)) v.push_back(*n);
    if (items.size() != 2 || v.size() != 2)
        throw UsageError(fmt::format("--guide-pixel {}: give X,Y, a pixel's column and row from the top left", text));
    return {int(v[0]), int(v[1])};
}

std::vector<const IntegratorInfo*> parse_algorithm_list(const std::string& spec) {
    std::vector<const IntegratorInfo*> infos;
    if (spec == "all") {  // every estimator, in `pathlab algorithms`' order
        for (const IntegratorInfo& info : integrators()) infos.push_back(&info);
        return infos;
    }
    for (const std::string& name : split_comma_list(spec)) {
        const IntegratorInfo* e = &integrator_or_usage_error(name);
        if (std::find(infos.begin(), infos.end(), e) != infos.end())
            throw UsageError(fmt::format("algorithm '{}' is listed twice", name));
        infos.push_back(e);
    }
    return infos;
}

}  // namespace pathlab
