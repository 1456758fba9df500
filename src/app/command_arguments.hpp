// Arguments shared by the render command and the subcommands (scene lists and algorithm
// names are resolved by job/scene_choice.hpp and job/render_job.hpp, included here). Bad values throw UsageError
// (exit code 2) with a message that lists what is valid.
#pragma once

#include <string>

#include "job/render_job.hpp"
#include "job/scene_choice.hpp"

namespace pathlab {

// Parses "WxH"; returns false if malformed or not positive.
bool parse_resolution(const std::string& text, int& width, int& height);
// --resolution: "" leaves 0x0 (the scene's own size); anything malformed is a UsageError.
void parse_resolution_option(const std::string& text, int& width, int& height);

}  // namespace pathlab
