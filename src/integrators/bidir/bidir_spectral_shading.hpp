// BSDF values at a path's wavelengths for the bidirectional integrators (lt, bdpt), in either
// transport mode (docs/spectral.md, "Spectral bdpt and the light tracer").
//
// spectral_shading.hpp re-evaluates a coloured model's value per lane from the radiance-mode
// model (Phong, the conductors), which is what a camera path needs. A light path scatters with
// the adjoint BSDF (bsdfs/bsdf_context.hpp): the radiance-mode value times
// Material::importance_factor, a scalar (the shading-normal correction; the refraction factor
// belongs to the dielectrics, whose grey value spectral_shading takes from the RGB evaluation,
// which applied it already). These wrappers add that factor where spectral_shading leaves it
// out, and sample a dispersive dielectric in either mode: the hero wavelength's index through
// Material::sample with the path's context (transport mode, reverse density), where
// spectral_shading's spectral_sample samples the bare model (radiance mode only).
#pragma once

#include <optional>

#include "integrators/common/shading.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

// The material's sample at the wavelengths: RGB mode's Material::sample(sp, ...) (the context's
// mode and reverse density), except at a dispersive dielectric, sampled with the hero
// wavelength's index, after which wl keeps only the hero (wl.terminate_secondary()).
std::optional<BsdfSample> bidir_spectral_sample(const ShadingPoint& sp, const Vec2f& u, SampledWavelengths& wl);

// The value of a sample drawn by bidir_spectral_sample (delta coefficients included), in sp's mode.
Spectrum4 bidir_spectral_sample_value(const ShadingPoint& sp, const BsdfSample& s, const SampledWavelengths& wl);

// The BSDF value towards the local direction wo, in sp's mode, when its RGB value f_rgb (from
// Material::eval or eval_and_pdf with the context sp) is known: 0 where f_rgb is 0.
Spectrum4 bidir_spectral_eval(const ShadingPoint& sp, const Vec3f& wo, const Rgb& f_rgb, const SampledWavelengths& wl);

// A contribution whose path went through a dispersive interface (its wavelengths reduced to the
// hero), expressed at the sample's 4 wavelengths: the film's estimator of (4 L_0, 0, 0, 0) with
// the 4 lanes' densities is that of L with the hero alone at density p(lambda_0) / 4
// (sampled_wavelengths.hpp), so contributions of one camera sample with and without dispersion
// can be summed before the film's conversion.
inline Spectrum4 hero_only(const Spectrum4& L) { return Spectrum4(4 * L[0], 0.0f, 0.0f, 0.0f); }

}  // namespace pathlab
