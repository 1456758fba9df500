// Small helpers shared by the tests that render.
#pragma once

#include <string>

#include "job/render_job.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::test {

inline RenderResult render_scene(const SceneDescription& desc, const std::string& algorithm, int width, int height,
                                 int spp, uint64_t seed = 1, IntegratorOptions options = {}) {
    JobRequest request;
    request.algorithm = algorithm;
    request.spp = uint64_t(spp);
    request.max_depth = options.max_depth;
    request.rr_depth = options.rr_depth;
    request.width = width;
    request.height = height;
    request.seed = seed;
    RenderJob job(scene_choice_of(desc), request);
    return job.run();
}

// A per-pixel estimator by name, for tests that call radiance() on chosen rays.
inline std::unique_ptr<PixelIntegrator> make_pixel_integrator(const std::string& name, const IntegratorOptions& options = {}) {
    std::unique_ptr<Integrator> i = find_integrator(name)->make(options);
    auto* p = dynamic_cast<PixelIntegrator*>(i.get());
    if (!p) throw std::invalid_argument(name + " is not a pixel integrator");
    i.release();
    return std::unique_ptr<PixelIntegrator>(p);
}

inline std::string shared_dir() { return PATHLAB_SHARED_DIR; }

}  // namespace pathlab::test
