// Factories of the estimators, one per file under src/render/ (declared here for the registry).
#pragma once

#include "integrators/integrator.hpp"

namespace pathlab {

std::unique_ptr<Estimator> make_eyelight(const EstimatorOptions&);
std::unique_ptr<Estimator> make_direct_light(const EstimatorOptions&);
std::unique_ptr<Estimator> make_direct_uniform(const EstimatorOptions&);
std::unique_ptr<Estimator> make_direct_cosine(const EstimatorOptions&);
std::unique_ptr<Estimator> make_direct_brdf(const EstimatorOptions&);
std::unique_ptr<Estimator> make_direct_mis(const EstimatorOptions&);
std::unique_ptr<Estimator> make_pt_naive(const EstimatorOptions&);
std::unique_ptr<Estimator> make_pt_mis3(const EstimatorOptions&);
std::unique_ptr<Estimator> make_pt_mis(const EstimatorOptions&);

}  // namespace pathlab
