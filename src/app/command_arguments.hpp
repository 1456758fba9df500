// Arguments shared by the render command and the subcommands (scene lists and algorithm
// names are resolved by job/scene_choice.hpp and job/render_job.hpp, included here). Bad values throw UsageError
// (exit code 2) with a message that lists what is valid.
#pragma once

#include <CLI/CLI.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

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

}  // namespace pathlab
