// Arguments shared by the render command and the subcommands. Bad values throw UsageError
// (exit code 2) with a message that lists what is valid.
#pragma once

#include <string>
#include <vector>

namespace pathlab {

struct EstimatorInfo;

// Parses "WxH"; returns false if malformed or not positive.
bool parse_resolution(const std::string& text, int& width, int& height);
// --resolution: "" leaves 0x0 (the scene's own size); anything malformed is a UsageError.
void parse_resolution_option(const std::string& text, int& width, int& height);

// The estimator named `name` (or its course alias); a UsageError listing them all otherwise.
const EstimatorInfo& estimator_or_usage_error(const std::string& name);

// "a,b,c" -> {"a", "b", "c"} (empty items kept, so that they are reported as unknown).
std::vector<std::string> split_comma_list(const std::string& spec);

// The built-in scene `key` (index, name or acronym); a UsageError listing them otherwise,
// which mentions scene files where the command takes them.
int builtin_scene_or_usage_error(const std::string& key, bool scene_files_allowed);

// "all" or a comma-separated list of built-in scenes, without repeats.
std::vector<int> parse_builtin_scene_list(const std::string& spec);

}  // namespace pathlab
