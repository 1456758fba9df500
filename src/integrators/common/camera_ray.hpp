// The camera ray of a pixel sample, shared by the estimators that start paths at the camera.
#pragma once

#include "cameras/camera.hpp"
#include "samplers/sampler.hpp"

namespace pathlab {

// The ray through raster position (x, y); a camera with a lens takes the sampler's next 2D
// number for the point on the lens (a pinhole takes none, so its paths' numbers do not shift).
inline Ray camera_ray(const PerspectiveCamera& camera, float x, float y, Sampler& sampler) {
    return camera.needs_lens_sample() ? camera.generate(x, y, sampler.next2d()) : camera.generate(x, y);
}

}  // namespace pathlab
