#include "integrators/guiding/guide_map.hpp"

#include "core/vec.hpp"
#include "integrators/guiding/ppg.hpp"

namespace pathlab {

Image guide_map(const SdTree& tree, const Vec3f& p, int width, int height) {
    Image map(width, height, Rgb(0.0f));
    const GuidingLeaf& leaf = tree.leaf(p);
    if (!leaf.usable) return map;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            // The square's point (u.x = (cos theta + 1) / 2, u.y = phi / 2 pi) at the pixel's centre.
            const Vec2f u(1.0f - (float(y) + 0.5f) / float(height), (float(x) + 0.5f) / float(width));
            // (the quadtree's density read on its own square, not through a direction and back)
            map.at(x, y) = Rgb(leaf.model == GuidingModel::kSdTree ? leaf.sampling.pdf(u) / (4.0f * kPi) : leaf.pdf(square_to_direction(u)));
        }
    return map;
}

const SdTree* trained_guide(const Integrator& integrator) {
    if (const auto* g = dynamic_cast<const PathGuiding<RgbTransport>*>(&integrator)) return g->trained() ? &g->tree() : nullptr;
    if (const auto* g = dynamic_cast<const PathGuiding<SpectralTransport>*>(&integrator)) return g->trained() ? &g->tree() : nullptr;
    return nullptr;
}

}  // namespace pathlab
