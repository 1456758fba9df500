// Which participating medium a scene renders, for the refusals of the methods that do not see
// media (an integrator, the path replay of `gradient` and `optimize`).
#pragma once

#include <string>

#include "scene/scene_description.hpp"

namespace pathlab {

// The first medium the scene renders (the camera's, or one on a side of a shape), and where,
// for the message of an integrator that cannot render media; "" when the scene has none (media
// declared and never referred to, and media of no extinction, change nothing).
// `only_grids`: heterogeneous media only.
std::string medium_in_use(const SceneDescription& d, bool only_grids = false);

}  // namespace pathlab
