#include "integrators/mlt/markov_chains.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

double mlt_contribution(const Vec3d& c) {
    return 0.2126 * std::abs(c.x) + 0.7152 * std::abs(c.y) + 0.0722 * std::abs(c.z);
}

ChainSample chain_sample(Vec2f raster, const Vec3d& film_colour) {
    ChainSample p;
    p.raster = raster;
    if (!is_finite(film_colour)) {
        p.invalid = true;
        return p;
    }
    p.colour = film_colour;
    p.contribution = mlt_contribution(film_colour);
    return p;
}

Vec2f raster_anywhere(const RenderContext& ctx, Vec2f u) {
    return {std::min(u.x * float(ctx.width), std::nextafter(float(ctx.width), 0.0f)),
            std::min(u.y * float(ctx.height), std::nextafter(float(ctx.height), 0.0f))};
}

}  // namespace pathlab
