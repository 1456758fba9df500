// Arguments shared by the render command and the subcommands (scene lists and algorithm
// names are resolved by job/scene_choice.hpp and job/render_job.hpp, included here). Bad values throw UsageError
// (exit code 2) with a message that lists what is valid.
#pragma once

#include <optional>

#include <tbb/global_control.h>

#include <CLI/CLI.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "image/image.hpp"
#include "job/render_job.hpp"
#include "job/scene_choice.hpp"

namespace pathlab {

constexpr int kMaxResolution = 1 << 15;      // the largest image edge
constexpr size_t kMaxThreadsPerCore = 8;     // --threads beyond this many per core are capped

// Parses "WxH" with whole numbers from 1 to kMaxResolution; false otherwise.
bool parse_resolution(const std::string& text, int& width, int& height);
// --resolution: "" leaves 0x0 (the scene's own size); anything malformed is a UsageError.
void parse_resolution_option(const std::string& text, int& width, int& height);
// --seed: a whole number from 0 to 2^64 - 1, digits only ("-1", "1e23" and 2^64 are UsageErrors,
// not numbers that wrap).
uint64_t parse_seed_option(const std::string& text);
// --threads: added to a command, and checked (a UsageError if not positive) and capped at
// kMaxThreadsPerCore x the cores, with a message, before it limits the thread pool.
void add_threads_option(CLI::App& app, int& threads);
size_t thread_count_or_cap(int requested);
// --threads applied: `limit` holds the pool to that many threads while it lives (0: no limit).
void limit_threads(std::optional<tbb::global_control>& limit, int threads);

// The scenes of every scene command, the same way everywhere: `pathlab SCENE... [options]`
// (Mitsuba's and pbrt's habit), or -s/--scene; each a built-in scene (index, name, acronym), a
// scene file, a comma-separated list of them, or 'all'; -D name=value for $name in scene files.
struct SceneArguments {
    std::vector<std::string> positional;
    std::string option;                 // -s/--scene
    std::vector<std::string> defines;   // -D name=value
};
void add_scene_arguments(CLI::App& app, SceneArguments& a);
// The list as one comma-separated spec ("" when no scene was given); both forms at once are a
// UsageError.
std::string scene_spec(const SceneArguments& a);
// The scenes, loaded: `fallback` (e.g. "all") when none was given, else a UsageError; also for
// unknown names, malformed files and defines no scene uses.
std::vector<SceneChoice> resolve_scene_arguments(const SceneArguments& a, const std::string& fallback = "");
SceneDefines parse_defines(const std::vector<std::string>& defines);

// --crop X,Y,W,H (pixels, from the top left; whole numbers, W and H positive). Whether it fits
// an image is checked against the image.
PixelRect parse_crop_option(const std::string& text);
// --guide-pixel X,Y: a pixel's column and row from the top left; a UsageError naming the option otherwise.
std::pair<int, int> parse_pixel_option(const std::string& text);

// -a/--algorithm in every command: one estimator or a comma-separated list (repeats refused).
std::vector<const IntegratorInfo*> parse_algorithm_list(const std::string& spec);

// The help text's note on signals, shared by every command that renders.
extern const char* const kInterruptHelp;

}  // namespace pathlab
