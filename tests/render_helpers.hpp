// Small helpers shared by the tests that render.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "job/render_job.hpp"
#include "job/renderer.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab::test {

inline RenderResult render_scene(const SceneDescription& desc, const std::string& algorithm, int width, int height,
                                 int spp, uint64_t seed = 1, IntegratorOptions options = {}) {
    JobRequest request;
    request.algorithm = algorithm;
    request.spp = uint64_t(spp);
    request.max_depth = options.max_depth;
    request.rr_depth = options.rr_depth;
    request.mis_power = options.mis_power;
    request.width = width;
    request.height = height;
    request.seed = seed;
    RenderJob job(scene_choice_of(desc), request);
    return job.run();
}

// A per-pixel estimator by name for transport T (RGB by default), for tests that call radiance()
// on chosen rays.
template <class T = RgbTransport>
std::unique_ptr<PixelIntegrator<T>> make_pixel_integrator(const std::string& name, IntegratorOptions options = {}) {
    options.spectral = T::spectral;
    std::unique_ptr<Integrator> i = find_integrator(name)->make(options);
    auto* p = dynamic_cast<PixelIntegrator<T>*>(i.get());
    if (!p) throw std::invalid_argument(name + " is not a pixel integrator");
    i.release();
    return std::unique_ptr<PixelIntegrator<T>>(p);
}

inline std::string shared_dir() { return PATHLAB_SHARED_DIR; }

// One render of a scene with a given integrator object (its options and faults as made).
inline RenderResult render_integrator(const SceneDescription& d, Integrator& integrator, int width, int height, uint64_t spp,
                                      uint64_t seed) {
    const auto scene = Scene::build(d);
    RenderSettings rs;
    rs.width = width, rs.height = height, rs.spp = spp, rs.seed = seed;
    return render(*scene, integrator, rs);
}

inline bool bit_identical(const Image& a, const Image& b) {
    return a.pixel_count() == b.pixel_count() && std::memcmp(a.data(), b.data(), a.pixel_count() * sizeof(Rgb)) == 0;
}

// The RMS difference of two Monte Carlo images with both images' own noise subtracted,
// sqrt(max(0, mean(d^2 - se_a^2 - se_b^2))): what is left is bias (0 when it is below the noise).
inline double bias_rms(const Image& a, const Image& se_a, const Image& b, const Image& se_b) {
    double sum = 0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double d = double(a[i][c]) - b[i][c];
            sum += d * d - double(se_a[i][c]) * se_a[i][c] - double(se_b[i][c]) * se_b[i][c];
        }
    return std::sqrt(std::max(0.0, sum / double(3 * a.pixel_count())));
}

}  // namespace pathlab::test
