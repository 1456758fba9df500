// Helpers shared by the image-judging subcommands.
#include <fmt/format.h>

#include "app/render_command.hpp"
#include "app/tool_commands.hpp"
#include "app/usage_error.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab {

std::vector<int> parse_builtin_scene_list(const std::string& spec) {
    std::vector<int> scenes;
    if (spec == "all") {
        for (const BuiltinSceneInfo& s : builtin_scenes()) scenes.push_back(s.index);
        return scenes;
    }
    size_t start = 0;
    while (start <= spec.size()) {
        const size_t comma = std::min(spec.find(',', start), spec.size());
        const std::string key = spec.substr(start, comma - start);
        const auto index = find_builtin_scene(key);
        if (!index) {
            std::string valid;
            for (const BuiltinSceneInfo& s : builtin_scenes()) valid += fmt::format("\n  {} {}", s.index, s.name);
            throw UsageError(fmt::format("unknown scene '{}'. Valid scenes (index or name, comma-separated, or 'all'):{}", key, valid));
        }
        if (std::find(scenes.begin(), scenes.end(), *index) == scenes.end()) scenes.push_back(*index);
        start = comma + 1;
    }
    return scenes;
}

void parse_resolution_option(const std::string& text, int& width, int& height) {
    width = height = 0;
    if (!text.empty() && !parse_resolution(text, width, height))
        throw UsageError(fmt::format("invalid --resolution '{}': expected WxH with positive integers, e.g. 512x512", text));
}

}  // namespace pathlab
