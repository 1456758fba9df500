// The integrators, each declared (name, aliases, parameters, factory) next to its code under
// src/integrators/<family>/ and listed in registry.cpp.
#pragma once

#include "integrators/integrator.hpp"

namespace pathlab {

const IntegratorInfo& eyelight_integrator();
const IntegratorInfo& direct_light_integrator();
const IntegratorInfo& direct_uniform_integrator();
const IntegratorInfo& direct_cosine_integrator();
const IntegratorInfo& direct_brdf_integrator();
const IntegratorInfo& direct_mis_integrator();
const IntegratorInfo& pt_naive_integrator();
const IntegratorInfo& pt_mis3_integrator();
const IntegratorInfo& pt_mis_integrator();
const IntegratorInfo& light_tracer_integrator();
const IntegratorInfo& bdpt_integrator();
const IntegratorInfo& sppm_integrator();
const IntegratorInfo& pm_integrator();
const IntegratorInfo& ic_integrator();
const IntegratorInfo& pbgi_integrator();
const IntegratorInfo& ppm_integrator();
const IntegratorInfo& vcm_integrator();
const IntegratorInfo& bpm_integrator();
const IntegratorInfo& upbp_integrator();
const IntegratorInfo& volpath_integrator();
const IntegratorInfo& pssmlt_integrator();
const IntegratorInfo& mmlt_integrator();
const IntegratorInfo& ppg_integrator();

}  // namespace pathlab
