// A material's values at a path's 4 wavelengths (spectral mode, docs/spectral.md): the BSDF's
// colour parameters as spectra (the scene file's own spectra, else their RGB upsampled), measured
// metals' eta and k, and dispersive dielectrics, which refract the hero wavelength with its own
// index and leave the path with the hero alone.
//
// The geometry of a path (directions, densities, lobe choices) is RGB mode's: sampling runs the
// material's RGB code, and only the colour of what was sampled is re-evaluated per wavelength.
// That is valid because no sampling decision of a supported model depends on a colour except
// through a density that eval does not use (Phong's lobe choice by mean reflectances: any
// positive density is a valid one), so f(lambda) cos / pdf stays unbiased lane by lane.
//
// `ctx` and `wi` are those of Material's own functions (bsdfs/material.hpp): the shading context
// (its transport mode, uv for textures) and the direction the path arrived from.
#pragma once

#include <optional>
#include <string>

#include "bsdfs/material.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

// "" when spectral mode renders the material, else the name of the model it does not support.
std::string spectral_unsupported_model(const Material& m);
// The material models spectral mode renders, for messages.
const char* spectral_material_names();

// Whether the material has a dispersive index (dielectric, roughdielectric): sampling and
// evaluating it reduce the wavelengths to the hero.
bool is_dispersive(const Material& m);

// The material's sample at the wavelengths wl: RGB mode's sample(), except at a dispersive
// dielectric, which refracts (and reflects) the hero wavelength with its index there and keeps
// only the hero (wl.terminate_secondary(): the other lanes' paths would part from it).
std::optional<BsdfSample> spectral_sample(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const Vec2f& u,
                                          SampledWavelengths& wl);
// The value at the wavelengths for directions (wi, wo) and its solid-angle density (RGB mode's
// eval_and_pdf, whose value is re-evaluated per lane); a dispersive interface reduces wl to the hero.
Spectrum4 spectral_eval_and_pdf(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, SampledWavelengths& wl,
                                float& pdf);
// The same value for an evaluation whose RGB value f_rgb is known already (0 there gives 0: a
// perturbed frame's side test, a refused direction).
Spectrum4 spectral_eval(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const Vec3f& wo, const Rgb& f_rgb,
                        const SampledWavelengths& wl);
// The value of a sample drawn by the material's RGB sample() (delta coefficients included).
Spectrum4 spectral_sample_value(const Material& m, const BsdfContext& ctx, const Vec3f& wi, const BsdfSample& s,
                                const SampledWavelengths& wl);

}  // namespace pathlab
