#include "integrators/photon/progressive_radius.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

double progressive_radius(double r1, double alpha, uint64_t i) {
    // r_i^2 = r_1^2 prod_{k=1}^{i-1} (k + alpha) / (k + 1) = r_1^2 Gamma(i + alpha) / (Gamma(1 + alpha) Gamma(i + 1))
    const double log_ratio = std::lgamma(double(i) + alpha) - std::lgamma(1 + alpha) - std::lgamma(double(i) + 1);
    return r1 * std::exp(0.5 * log_ratio);
}

float initial_photon_radius(const RenderContext& ctx, const IntegratorOptions& options) {
    if (options.photon_radius > 0) return options.photon_radius;
    // A pixel's angular width times the distance of the scene's centre.
    const float angle = ctx.camera.pixel_angle();
    const float distance = length(ctx.scene.scene_sphere().center - ctx.camera.position());
    return std::max(2 * angle * distance, 1e-4f * ctx.scene.scene_sphere().radius);
}

std::vector<ParamInfo> progressive_radius_params() {
    return {{"initial_radius", ParamType::Float, "0", "the first iteration's radius (0: two pixel footprints at the scene's centre; --radius wins)",
             "initialRadius"},
            {"alpha", ParamType::Float, "0.666667", "the radius reduction, in (0, 1] (--alpha wins)"}};
}

}  // namespace pathlab
