// A contribution whose path went through a dispersive interface (its wavelengths reduced to the
// hero), expressed at the sample's 4 wavelengths (docs/spectral.md, "Spectral bdpt and the light
// tracer"): the film's estimator of (4 L_0, 0, 0, 0) with the 4 lanes' densities is that of L with
// the hero alone at density p(lambda_0) / 4 (sampled_wavelengths.hpp), so contributions of one
// camera sample with and without dispersion can be summed before the film's conversion.
#pragma once

#include "spectral/spectrum4.hpp"

namespace pathlab {

inline Spectrum4 hero_only(const Spectrum4& L) { return Spectrum4(4 * L[0], 0.0f, 0.0f, 0.0f); }

}  // namespace pathlab
