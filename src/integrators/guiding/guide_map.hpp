// What ppg's SD-tree learned at a point: the guiding density of the spatial leaf holding it (its
// quadtree, or with --guiding vmm its mixture), as
// an image of the sphere of directions for the comparison report (`pathlab report
// --guide-pixel`, issue 39).
#pragma once

#include "image/image.hpp"
#include "integrators/guiding/sd_tree.hpp"
#include "integrators/integrator.hpp"

namespace pathlab {

// The leaf's sampling density over the quadtree's own square of cylindrical coordinates, which is
// an equal-area map of the sphere (sd_tree.hpp): column x is phi = 2 pi (x + 1/2) / width from
// +x towards +y, row y is cos theta = 1 - 2 (y + 1/2) / height from +z (top) to -z; each pixel
// holds the solid-angle density (per steradian, grey), so that the pixels' sum times 4 pi /
// (width height) is 1 where the leaf guides. All 0 where it does not (no energy learned).
Image guide_map(const SdTree& tree, const Vec3f& p, int width = 256, int height = 128);

// The trained SD-tree of a ppg integrator (RGB or spectral), none for another integrator or
// before training.
const SdTree* trained_guide(const Integrator& integrator);

}  // namespace pathlab
