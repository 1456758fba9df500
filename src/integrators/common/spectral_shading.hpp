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

// Emitted radiance at the wavelengths: `Le` is what light `light` (an index into scene.lights(),
// or -1) gave in RGB (a LightSample's or EmissionSample's Le, a surface emitter's radiance, the
// environment's). Every integrator turns emission into a spectrum through these, never through
// illuminant_spectrum directly, so that emitters with a spectrum of their own (a black body)
// are seen with it.
Spectrum4 emission_spectrum(const Scene& scene, int light, const Rgb& Le, const SampledWavelengths& wl);
// The environment's radiance along an escaped ray's direction d (black without an environment).
Spectrum4 escaped_spectrum(const Scene& scene, const Vec3f& d, const SampledWavelengths& wl);
// The radiance a surface emitter at `hit` sends in direction w (black for other surfaces).
Spectrum4 emitted_spectrum(const Scene& scene, const Intersection& hit, const Vec3f& w, const SampledWavelengths& wl);

// "" when spectral mode renders the material, else the name of the model it does not support yet.
std::string spectral_unsupported_model(const Material& m);
// The material models spectral mode renders, for messages.
const char* spectral_material_names();

// Whether the material has a dispersive index (dielectric, roughdielectric): sampling and
// evaluating it reduce the wavelengths to the hero.
bool is_dispersive(const Material& m);

// The material's sample at the wavelengths wl: RGB mode's sample(), except at a dispersive
// dielectric, which refracts (and reflects) the hero wavelength with its index there and keeps
// only the hero (wl.terminate_secondary(): the other lanes' paths would part from it).
std::optional<BsdfSample> spectral_sample(const ShadingPoint& sp, const Vec2f& u, SampledWavelengths& wl);

// The BSDF value at the wavelengths for directions (sp.wi, wo) and its solid-angle density
// (RGB mode's eval_and_pdf, whose value is re-evaluated per lane). Every non-delta evaluation
// in spectral mode goes through it: a dispersive interface may reduce wl to the hero.
Spectrum4 spectral_eval_and_pdf(const ShadingPoint& sp, const Vec3f& wo, SampledWavelengths& wl, float& pdf);
// The same value for an evaluation whose RGB value f_rgb is known already (0 there gives 0: a
// perturbed frame's side test, a refused direction).
Spectrum4 spectral_eval(const ShadingPoint& sp, const Vec3f& wo, const Rgb& f_rgb, const SampledWavelengths& wl);
// The value of a sample drawn by the material's RGB sample() (delta coefficients included).
Spectrum4 spectral_sample_value(const ShadingPoint& sp, const BsdfSample& s, const SampledWavelengths& wl);

}  // namespace pathlab
