// The radius of the progressive photon methods (sppm, vcm, bpm), per iteration, in Knaus and
// Zwicker's probabilistic formulation (2011): r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1), a function of
// the iteration index alone, so iterations are independent and a render split into parts gives
// the same result as one.
#pragma once

#include <cstdint>

#include "integrators/integrator.hpp"

namespace pathlab {

// The radius of iteration i (1-based) for the first radius r1.
double progressive_radius(double r1, double alpha, uint64_t i);

// The first radius: --radius if given, else two pixel footprints at the distance of the scene's
// centre, so that the blur starts at the scale of a pixel whatever the resolution.
float initial_photon_radius(const RenderContext& ctx, const IntegratorOptions& options);

// The scene-file parameters of the radius: initial_radius and alpha (Mitsuba 0.6's initialRadius).
std::vector<ParamInfo> progressive_radius_params();

}  // namespace pathlab
