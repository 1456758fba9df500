// Which scene a render is of: a built-in course scene (by index, name or the course's acronym)
// or a scene file, resolved from what a user typed, with the names that output patterns use.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "scene/scene_description.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab {

struct SceneChoice {
    std::string name;            // {scene}: the built-in scene's name, or the scene file's stem
    std::string index;           // {index}: the course index, or the scene file's stem
    std::optional<int> builtin;  // the course index of a built-in scene
    std::string file;            // the scene file, if any
    SceneDescription description;
    SceneParameters parameters;  // a scene file's $name parameters, with the values they took
    std::vector<std::string> files;  // every file the scene read: the scene file, its includes, spectra, meshes, emitters' files
    std::string hash;            // scene_hash(*this), when it was resolved
};

// What a scene is, as 16 hex digits (XXH3, 64 bits), for everything that must know whether two
// renders or a render and a reference are of the same scene (reference manifests, the EXR's
// pathlab:sceneHash, checkpoints, merge): the bytes of every file the scene read (a built-in
// scene: its index), its $parameters' values, and its description's camera and geometry. The
// same file with another -D value, or with an included file or a mesh edited, is another scene;
// the files' names and folders do not count (a copied scene is the same scene).
std::string scene_hash(const SceneChoice& scene);

// True for a key that names a scene file (ends in .xml, or .gltf or .glb: a glTF scene).
bool looks_like_scene_file(const std::string& key);

// "3", "ceiling-glossy", "ws_c_sdsgwdwg", "scenes/x.xml", "all" or a comma-separated list of
// them. Unknown names and malformed scene files (file:line:column) are UsageErrors; scene files
// are refused with a UsageError unless `allow_files`. A define that no scene of the list uses
// (no $name) is a UsageError listing the parameters the scenes have.
std::vector<SceneChoice> resolve_scenes(const std::string& spec, const SceneDefines& defines = {}, bool allow_files = true);
SceneChoice builtin_scene_choice(int index);
// A scene made by the caller (tests, benchmarks): named after desc.name.
SceneChoice scene_choice_of(SceneDescription desc);

// The built-in scene `key` (index, name or acronym); a UsageError listing them otherwise,
// which mentions scene files where the command takes them.
int builtin_scene_or_usage_error(const std::string& key, bool scene_files_allowed);
// "all" or a comma-separated list of built-in scenes, without repeats.
std::vector<int> parse_builtin_scene_list(const std::string& spec);

// "a,b,c" -> {"a", "b", "c"} (empty items kept, so that they are reported as unknown).
std::vector<std::string> split_comma_list(const std::string& spec);

}  // namespace pathlab
