// The hemisphere-sampling direct estimators (direct_sampling.cpp) in spectral mode.
#pragma once

#include "scene/scene.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

// direct_sampling.cpp's strategies, in its order.
enum class DirectSamplingStrategy { UniformHemisphere, CosineHemisphere, Brdf };

Spectrum4 direct_sampling_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, SampledWavelengths& wl, DirectSamplingStrategy strategy,
                                   bool hide);

}  // namespace pathlab
