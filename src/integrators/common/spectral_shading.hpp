// Spectral mode's values at a path's 4 wavelengths (docs/spectral.md, phase 2): RGB inputs
// upsampled (Jakob and Hanika 2019), the BSDF's value f and the emitters' radiance.
//
// The geometry of a path (directions, densities, lobe choices, MIS weights, light selection) is
// RGB mode's: sampling runs the material's and the light's RGB code, and only the colour of what
// was sampled is re-evaluated per wavelength here. That is valid because no sampling decision of
// a supported model depends on a colour except through a density that eval does not use (Phong's
// lobe choice by mean reflectances: any positive density is a valid one), so the estimator
// f(lambda) cos / pdf stays unbiased lane by lane.
//
// Colours become spectra through a per-thread cache of the table's lookups keyed by the exact
// RGB bits, so a constant colour is looked up once per thread (a hit pays the 4-lane sigmoid
// only) and textured colours per hit; the cache returns exactly what the lookup would, so images
// do not depend on threads.
#pragma once

#include <string>

#include "integrators/common/shading.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

// A reflectance (RgbAlbedoSpectrum; a colour above 1 as RgbUnboundedSpectrum), any non-negative
// value (RgbUnboundedSpectrum), an emitter's radiance (RgbIlluminantSpectrum: times D65 at unit
// luminance), each at the 4 wavelengths.
Spectrum4 reflectance_spectrum(const Rgb& rgb, const SampledWavelengths& wl);
Spectrum4 unbounded_spectrum(const Rgb& rgb, const SampledWavelengths& wl);
Spectrum4 illuminant_spectrum(const Rgb& rgb, const SampledWavelengths& wl);

// "" when spectral mode renders the material, else the name of the model it does not support yet.
std::string spectral_unsupported_model(const Material& m);
// The material models spectral mode renders, for messages.
const char* spectral_material_names();

// The material's sample at the wavelengths wl: RGB mode's sample(), except at a dispersive
// dielectric, which refracts (and reflects) the hero wavelength with its index there and keeps
// only the hero (wl.terminate_secondary(): the other lanes' paths would part from it).
std::optional<BsdfSample> spectral_sample(const ShadingPoint& sp, const Vec2f& u, SampledWavelengths& wl);

// The BSDF value at the wavelengths for directions (sp.wi, wo) of a non-delta evaluation whose
// RGB value was f_rgb (0 there gives 0: a perturbed frame's side test, a refused direction).
Spectrum4 spectral_eval(const ShadingPoint& sp, const Vec3f& wo, const Rgb& f_rgb, const SampledWavelengths& wl);
// The value of a sample drawn by the material's RGB sample() (delta coefficients included).
Spectrum4 spectral_sample_value(const ShadingPoint& sp, const BsdfSample& s, const SampledWavelengths& wl);

}  // namespace pathlab
