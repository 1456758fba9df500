// Factories of the integrators, one per file under src/integrators/<family>/ (declared here for the registry).
#pragma once

#include "integrators/integrator.hpp"

namespace pathlab {

std::unique_ptr<Integrator> make_eyelight(const IntegratorOptions&);
std::unique_ptr<Integrator> make_direct_light(const IntegratorOptions&);
std::unique_ptr<Integrator> make_direct_uniform(const IntegratorOptions&);
std::unique_ptr<Integrator> make_direct_cosine(const IntegratorOptions&);
std::unique_ptr<Integrator> make_direct_brdf(const IntegratorOptions&);
std::unique_ptr<Integrator> make_direct_mis(const IntegratorOptions&);
std::unique_ptr<Integrator> make_pt_naive(const IntegratorOptions&);
std::unique_ptr<Integrator> make_pt_mis3(const IntegratorOptions&);
std::unique_ptr<Integrator> make_pt_mis(const IntegratorOptions&);
std::unique_ptr<Integrator> make_light_tracer(const IntegratorOptions&);

}  // namespace pathlab
