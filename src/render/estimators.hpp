// Factories of the estimators, one per file under src/render/ (declared here for the registry).
#pragma once

#include "render/estimator.hpp"

namespace pathlab {

std::unique_ptr<Estimator> make_eyelight(const EstimatorOptions&);
std::unique_ptr<Estimator> make_direct_light(const EstimatorOptions&);

}  // namespace pathlab
