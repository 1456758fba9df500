// The photon methods' spectral-mode integrators (pm_spectral.cpp, sppm_spectral.cpp), made by
// pm's, ppm's and sppm's IntegratorInfo::make when IntegratorOptions::spectral is set. A header
// of declarations only, so that RGB mode's translation units (pm.cpp, sppm.cpp) include nothing
// spectral.
#pragma once

#include <memory>

#include "integrators/integrator.hpp"

namespace pathlab {

// sppm (jittered camera rays) or ppm (pixel_centres) in spectral mode.
std::unique_ptr<Integrator> make_spectral_sppm(const IntegratorOptions& options, bool pixel_centres);
// pm in spectral mode: photon maps per pass.
std::unique_ptr<Integrator> make_spectral_pm(const IntegratorOptions& options);

}  // namespace pathlab
