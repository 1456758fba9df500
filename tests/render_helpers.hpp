// Small helpers shared by the tests that render.
#pragma once

#include <string>

#include "job/renderer.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::test {

inline RenderResult render_scene(const SceneDescription& desc, const std::string& algorithm, int width, int height,
                                 int spp, uint64_t seed = 1, EstimatorOptions options = {}) {
    const auto scene = Scene::build(desc);
    const EstimatorInfo* info = find_estimator(algorithm);
    if (!info) throw std::invalid_argument("unknown algorithm " + algorithm);
    const auto estimator = info->make(options);
    RenderSettings rs;
    rs.width = width;
    rs.height = height;
    rs.spp = spp;
    rs.seed = seed;
    return render(*scene, *estimator, rs);
}

inline std::string shared_dir() { return PATHLAB_SHARED_DIR; }

}  // namespace pathlab::test
