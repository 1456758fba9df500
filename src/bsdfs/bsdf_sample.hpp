// What every BSDF's sample() returns. Conventions (shared by all materials, see material.hpp):
// local shading frame with the normal +z, `wi` towards the camera side, `wo` sampled.
#pragma once

#include "core/vec.hpp"

namespace pathlab {

// One sampled direction of a BSDF. `f` is the BSDF value (no cosine), `pdfW` the solid-angle
// density of `wo`. For a delta lobe (`delta`), `f` and `pdfW` are both the coefficient of the
// Dirac delta so that f / pdfW is the weight; eval() and pdf() are zero for such directions.
// For a material mixing delta and non-delta lobes (plastic), a sample of a non-delta lobe has
// f = eval() and pdfW = pdf() (which include only the non-delta lobes and their selection
// probabilities), and a sample of the delta lobe has pdfW = the probability of choosing it.
struct BsdfSample {
    Vec3f wo;
    Rgb f;
    float pdfW = 0;
    bool delta = false;
};

}  // namespace pathlab
