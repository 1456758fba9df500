#include "job/scene_choice.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "job/usage_error.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab {

bool looks_like_scene_file(const std::string& key) {
    return key.size() > 4 && key.compare(key.size() - 4, 4, ".xml") == 0;
}

SceneChoice builtin_scene_choice(int index) {
    return {builtin_scenes()[size_t(index)].name, std::to_string(index), index, "", make_builtin_scene(index), {}, ""};
}

SceneChoice scene_choice_of(SceneDescription desc) {
    std::string name = desc.name;
    return {name, name, std::nullopt, "", std::move(desc), {}, ""};
}

std::string scene_file_hash(const std::string& path, const SceneParameters& parameters) {
    uint64_t h = 14695981039346656037ull;  // FNV-1a offset basis
    const auto add = [&h](unsigned char c) { h = (h ^ c) * 1099511628211ull; };
    std::ifstream in(path, std::ios::binary);
    for (std::istreambuf_iterator<char> it(in), end; it != end; ++it) add(static_cast<unsigned char>(*it));
    for (const auto& [name, value] : parameters)
        for (const char c : "\n" + name + "=" + value) add(static_cast<unsigned char>(c));
    return fmt::format("{:016x}", h);
}

namespace {

// A -D name that no scene of the list uses is a typo (`-D sp=8` for spp) or meant for another
// scene: an error that lists what the scenes take.
void check_defines_used(const std::vector<SceneChoice>& scenes, const SceneDefines& defines) {
    for (const auto& [name, value] : defines) {
        if (std::any_of(scenes.begin(), scenes.end(), [&](const SceneChoice& s) { return s.parameters.count(name) > 0; })) continue;
        std::string listing;
        bool builtin = false;
        for (const SceneChoice& s : scenes) {
            if (s.file.empty()) {
                builtin = true;
                continue;
            }
            std::vector<std::string> params;
            for (const auto& [p, v] : s.parameters) params.push_back(fmt::format("{} (now {})", p, v));
            listing += fmt::format("\n  {}: {}", s.file, params.empty() ? "none (no $name in it)" : fmt::format("{}", fmt::join(params, ", ")));
        }
        if (builtin) listing += "\n  the built-in scenes take no parameters";
        throw UsageError(fmt::format("-D {}={}: no scene uses ${}. The scenes' parameters:{}", name, value, name, listing));
    }
}

}  // namespace

std::vector<SceneChoice> resolve_scenes(const std::string& spec, const SceneDefines& defines, bool allow_files) {
    std::vector<SceneChoice> out;
    if (spec == "all") {
        for (const BuiltinSceneInfo& s : builtin_scenes()) out.push_back(builtin_scene_choice(s.index));
        check_defines_used(out, defines);
        return out;
    }
    for (const std::string& key : split_comma_list(spec)) {
        if (allow_files && looks_like_scene_file(key)) {
            try {
                const std::string stem = std::filesystem::path(key).stem().string();
                SceneParameters used;
                SceneDescription description = load_scene_file(key, defines, &used);
                std::string hash = scene_file_hash(key, used);
                out.push_back({stem, stem, std::nullopt, key, std::move(description), std::move(used), std::move(hash)});
            } catch (const SceneFileError& e) {
                throw UsageError(e.what());
            }
        } else if (key == "all") {
            for (const BuiltinSceneInfo& s : builtin_scenes()) out.push_back(builtin_scene_choice(s.index));
        } else {
            out.push_back(builtin_scene_choice(builtin_scene_or_usage_error(key, allow_files)));
        }
    }
    check_defines_used(out, defines);
    return out;
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
