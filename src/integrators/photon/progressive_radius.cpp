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
    // The angle between the rays through two neighbouring pixels at the image centre, times the
    // distance of the scene's centre.
    const float cx = 0.5f * float(ctx.width), cy = 0.5f * float(ctx.height);
    const Vec3f a = normalize(ctx.camera.generate(cx, cy).d), b = normalize(ctx.camera.generate(cx + 1, cy).d);
    const float angle = 2 * std::asin(std::min(1.0f, 0.5f * length(a - b)));
    const float distance = length(ctx.scene.scene_sphere().center - ctx.camera.position());
    return std::max(2 * angle * distance, 1e-4f * ctx.scene.scene_sphere().radius);
}

}  // namespace pathlab
