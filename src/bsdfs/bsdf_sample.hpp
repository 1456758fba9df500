// What every BSDF's sample() returns, and the flags of its lobes. Conventions (shared by all
// materials, see material.hpp): local shading frame with the normal +z, `wi` the direction the
// path arrived from, `wo` sampled.
#pragma once

#include <cstdint>

#include "core/vec.hpp"

namespace pathlab {

// Lobe flags: the kind of scattering (diffuse, glossy, specular = a Dirac delta) and its side.
// kLobeNull marks a straight pass through the surface, wo = -wi, as if it were not there
// (thindielectric's transmission, a mask's hole; always with kLobeSpecular | kLobeTransmission):
// Mitsuba's BSDFFlags::Null, which its volpath does not count as a bounce (--null-depth skip).
enum BsdfLobe : uint32_t {
    kLobeDiffuse = 1,
    kLobeGlossy = 2,
    kLobeSpecular = 4,
    kLobeReflection = 8,
    kLobeTransmission = 16,
    kLobeNull = 32,
};

// One sampled direction of a BSDF. `f` is the BSDF value (no cosine), `pdfW` the solid-angle
// density of `wo`. For a delta lobe (`delta`), `f` and `pdfW` are both the coefficient of the
// Dirac delta so that f / pdfW is the weight; eval() and pdf() are zero for such directions.
// For a material mixing delta and non-delta lobes (plastic), a sample of a non-delta lobe has
// f = eval() and pdfW = pdf() (which include only the non-delta lobes and their selection
// probabilities), and a sample of the delta lobe has pdfW = the probability of choosing it.
// `lobe` holds the flags of the lobe that was sampled; `pdf_rev`, the density of wi had the
// path come from wo (pdf(wo, wi)), is filled in only when the context asks for it (bidirectional
// methods); for a delta lobe it is the probability of choosing the same lobe from wo, which for
// every delta lobe here equals pdfW (Fresnel terms are symmetric).
struct BsdfSample {
    Vec3f wo;
    Rgb f;
    float pdfW = 0;
    bool delta = false;
    uint32_t lobe = 0;
    float pdf_rev = 0;
};

}  // namespace pathlab
