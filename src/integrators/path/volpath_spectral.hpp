// volpath in spectral mode (docs/spectral.md, "Spectral direct estimators, eyelight and
// volpath"): volpath.cpp's loop with the path's values at the wavelengths wl, media through
// integrators/common/spectral_media.hpp (coefficients upsampled, the hero lane driving free
// flights, spectral MIS over the 4 lanes). A copy of the loop in its own file, as
// pt_mis_spectral.cpp, so that RGB mode's translation unit compiles as before.
#pragma once

#include "integrators/common/path_rules.hpp"
#include "scene/scene.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

struct VolpathSpectralSettings {
    bool mis = true;                   // VolpathSettings::mis
    bool pt_mis_without_media = true;  // VolpathSettings::pt_mis_without_media (pt_mis_spectral_from_hit)
    bool hide_emitters = false;
    // > 1: free flights and transmittances in every medium by delta and ratio tracking against
    // this multiple of the majorant (null collisions in homogeneous media too): another
    // free-flight strategy with the same expectation, for the tests.
    float majorant_factor = 1;
};

Spectrum4 volpath_spectral_radiance(const Scene& scene, const Ray& camera_ray, Sampler& sampler, SampledWavelengths& wl,
                                    const PathRules& rules, const VolpathSpectralSettings& settings);

}  // namespace pathlab
