// The 8 Cornell-box scenes of the NPGR010 course, exactly as specified in
// ../shared/npgr010-scenes.md (geometry, camera, materials, light radiances).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "scene/scene_description.hpp"

namespace pathlab {

struct BuiltinSceneInfo {
    int index;
    std::string name;     // e.g. "ceiling-glossy"
    std::string acronym;  // the course's file stem, e.g. "ws_c_sdsgwdwg"
    std::string summary;
};

const std::vector<BuiltinSceneInfo>& builtin_scenes();
// Accepts the course index ("3"), the name ("ceiling-glossy") or the course acronym.
std::optional<int> find_builtin_scene(const std::string& key);
SceneDescription make_builtin_scene(int index);

}  // namespace pathlab
