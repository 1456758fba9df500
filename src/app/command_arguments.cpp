#include "app/command_arguments.hpp"

#include <algorithm>
#include <cstdio>

#include <fmt/format.h>

#include "app/usage_error.hpp"
#include "integrators/integrator.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab {

bool parse_resolution(const std::string& text, int& width, int& height) {
    char x = 0;
    char rest = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &x, &height, &rest) != 3 || (x != 'x' && x != 'X')) return false;
    return width > 0 && height > 0 && width <= 1 << 15 && height <= 1 << 15;
}

void parse_resolution_option(const std::string& text, int& width, int& height) {
    width = height = 0;
    if (!text.empty() && !parse_resolution(text, width, height))
        throw UsageError(fmt::format("invalid --resolution '{}': expected WxH with positive integers, e.g. 512x512", text));
}

const EstimatorInfo& estimator_or_usage_error(const std::string& name) {
    const EstimatorInfo* info = find_estimator(name);
    if (!info) throw UsageError(fmt::format("unknown algorithm '{}'. Valid algorithms: {}", name, estimator_names()));
    return *info;
}

std::vector<std::string> split_comma_list(const std::string& spec) {
    std::vector<std::string> items;
    size_t start = 0;
    while (start <= spec.size()) {
        const size_t comma = std::min(spec.find(',', start), spec.size());
        items.push_back(spec.substr(start, comma - start));
        start = comma + 1;
    }
    return items;
}

int builtin_scene_or_usage_error(const std::string& key, bool scene_files_allowed) {
    if (const auto index = find_builtin_scene(key)) return *index;
    std::string valid;
    for (const BuiltinSceneInfo& s : builtin_scenes()) valid += fmt::format("\n  {} {}", s.index, s.name);
    throw UsageError(fmt::format("unknown scene '{}'. Valid scenes (index or name, comma-separated, or 'all'){}:{}", key,
                                 scene_files_allowed ? ", or a scene file ending in .xml" : "", valid));
}

std::vector<int> parse_builtin_scene_list(const std::string& spec) {
    std::vector<int> scenes;
    if (spec == "all") {
        for (const BuiltinSceneInfo& s : builtin_scenes()) scenes.push_back(s.index);
        return scenes;
    }
    for (const std::string& key : split_comma_list(spec)) {
        const int index = builtin_scene_or_usage_error(key, /*scene_files_allowed=*/false);
        if (std::find(scenes.begin(), scenes.end(), index) == scenes.end()) scenes.push_back(index);
    }
    return scenes;
}

}  // namespace pathlab
