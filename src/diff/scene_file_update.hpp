// The scene file an optimisation started from, rewritten with the optimised parameter values:
// each parameter's element is found by the id of its <bsdf> (inside a twosided wrapper too),
// <shape> (its <emitter>) or <emitter>, and its value set (an <rgb> or <float> written where the
// file gave another form or left the default). A <path> to the original file's folder is added
// first, so that the new file finds the meshes wherever it is written. Comments and everything
// else are kept as they were.
#pragma once

#include <string>
#include <vector>

#include "diff/parameters.hpp"

namespace pathlab {

// The rewritten file's text; std::runtime_error naming the file and the id when an element is
// not in that file itself (declared in an <include>d file, say).
std::string scene_file_with_values(const std::string& scene_file, const ParameterSet& set, const std::vector<float>& theta);

}  // namespace pathlab
