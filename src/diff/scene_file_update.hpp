// The scene file an optimisation started from, rewritten with the optimised parameter values:
// each parameter's element is found by the id of its <bsdf> (inside a twosided wrapper too),
// <shape> (its <emitter>), <emitter> or <medium>, and its value set (an <rgb> or <float> written where the
// file gave another form or left the default). A <path> to the original file's folder is added
// first, so that the new file finds the meshes wherever it is written. Comments and everything
// else are kept as they were.
//
// Texels (`<id>.reflectance.data`) are written as an image by the caller (an EXR: the linear
// values as they are, see docs/differentiable.md); the rewrite points the bitmap's `filename`
// (the <texture> nested in the BSDF under the parameter's name, or the top-level one its <ref>
// names) at that file, named in `texel_files` by parameter name.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "diff/parameters.hpp"

namespace pathlab {

// A homogeneous <medium>'s parameters are written as its sigma_t and albedo together (whatever
// form the file gave, sigma_a and sigma_s or a scale), taken from `with_values`: the scene's
// description with theta set (required for them).
//
// The rewritten file's text; std::runtime_error naming the file and the id when an element is
// not in that file itself (declared in an <include>d file, say).
std::string scene_file_with_values(const std::string& scene_file, const ParameterSet& set, const std::vector<float>& theta,
                                   const std::map<std::string, std::string>& texel_files = {},
                                   const SceneDescription* with_values = nullptr);

}  // namespace pathlab
