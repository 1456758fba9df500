// pt_mis_from_hit (pt_mis.hpp) in spectral mode: the same path (random numbers, directions,
// densities, MIS weights; roulette on the largest lane of the spectral throughput), its values
// at the wavelengths wl (integrators/common/spectral_shading.hpp). A copy of the loop in its own
// file rather than a template of it, so that RGB mode's translation unit compiles (and inlines)
// exactly as before: the hot loop is literally today's code.
#pragma once

#include "integrators/common/path_rules.hpp"
#include "scene/scene.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

Spectrum4 pt_mis_spectral_from_hit(const Scene& scene, Intersection hit, Vec3f dir, int first_bounce, Sampler& sampler,
                                   const PathRules& rules, bool three_rays, int only_length, Spectrum4 L, SampledWavelengths& wl);

}  // namespace pathlab
