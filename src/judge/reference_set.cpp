#include "judge/reference_set.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/input_file.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

std::string trim(const std::string& s) {
    const auto not_space = [](unsigned char c) { return !std::isspace(c); };
    const auto b = std::find_if(s.begin(), s.end(), not_space);
    const auto e = std::find_if(s.rbegin(), s.rend(), not_space).base();
    return b < e ? std::string(b, e) : std::string();
}

std::string lower_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

ReferenceFile make_reference_file(const std::string& path) {
    ReferenceFile ref{path, lower_extension(path) == ".png" ? ReferenceKind::Course8bit : ReferenceKind::Linear, {}};
    if (ref.kind == ReferenceKind::Linear && fs::exists(stderr_path_for(path))) ref.stderr_path = stderr_path_for(path);
    return ref;
}

std::optional<ReferenceFile> first_existing(const std::string& dir, const std::vector<std::string>& names, std::string* tried) {
    for (const std::string& name : names) {
        const fs::path p = fs::path(dir) / name;
        if (fs::is_regular_file(p)) return make_reference_file(p.string());
    }
    if (tried) *tried = fmt::format("{}/{{{}}}", dir, fmt::join(names, ","));
    return std::nullopt;
}

}  // namespace

std::vector<std::string> expected_reference_names(int scene) {
    const BuiltinSceneInfo& s = builtin_scenes().at(size_t(scene));
    const std::string i = std::to_string(s.index);
    const std::vector<std::string> stems = {i + "-" + s.name, i, s.name, s.acronym, i + "_" + s.acronym};
    std::vector<std::string> names;
    for (const std::string& stem : stems)
        for (const char* ext : {".exr", ".pfm", ".hdr"}) names.push_back(stem + ext);
    for (const std::string& stem : stems) names.push_back(stem + ".png");
    return names;
}

std::string stderr_path_for(const std::string& image_path) {
    const fs::path p(image_path);
    return (p.parent_path() / (p.stem().string() + ".stderr" + p.extension().string())).string();
}

std::map<int, std::string> read_reference_mapping(const std::string& path) {
    std::istringstream in;
    try {
        in.str(read_input_file(path, uint64_t(1) << 20));
    } catch (const InputFileError& e) {
        throw ReferenceMappingError(fmt::format("{}: cannot read the mapping file: {}", path, e.what()));
    }
    std::map<int, std::string> mapping;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        line = trim(line.substr(0, line.find('#')));
        if (line.empty()) continue;
        const size_t eq = line.find('=');
        const std::string key = eq == std::string::npos ? "" : trim(line.substr(0, eq));
        const std::string file = eq == std::string::npos ? "" : trim(line.substr(eq + 1));
        if (key.empty() || file.empty())
            throw ReferenceMappingError(fmt::format("{}:{}: expected 'scene = file', got '{}'", path, number, line));
        const auto scene = find_builtin_scene(key);
        if (!scene)
            throw ReferenceMappingError(fmt::format("{}:{}: unknown scene '{}' (an index 0-7, a name or an acronym, see `pathlab scenes`)",
                                                    path, number, key));
        if (mapping.count(*scene))
            throw ReferenceMappingError(fmt::format("{}:{}: scene '{}' is mapped twice", path, number, key));
        mapping[*scene] = file;
    }
    return mapping;
}

std::optional<ReferenceFile> find_reference(const std::string& dir, int scene, const std::map<int, std::string>& mapping,
                                            std::string* tried) {
    if (const auto it = mapping.find(scene); it != mapping.end()) {
        const fs::path p = fs::path(it->second).is_absolute() ? fs::path(it->second) : fs::path(dir) / it->second;
        if (tried) *tried = p.string() + " (from the mapping file)";
        if (fs::is_regular_file(p)) return make_reference_file(p.string());
        return std::nullopt;
    }
    const std::vector<std::string> names = expected_reference_names(scene);
    return first_existing(dir, names, tried);
}

std::optional<ReferenceFile> find_reference_named(const std::string& dir, const std::string& stem, std::string* tried) {
    return first_existing(dir, {stem + ".exr", stem + ".pfm", stem + ".hdr", stem + ".png"}, tried);
}

}  // namespace pathlab
