// The estimator interface and the registry of estimators selectable by name.
// To add an estimator: implement Estimator in one file under src/render/ and add one entry to
// the table in estimator_registry.cpp.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "samplers/sampler.hpp"
#include "scene/scene.hpp"

namespace pathlab {

struct EstimatorOptions {
    int max_depth = -1;  // longest path in bounces (1 = direct illumination only); -1 = unlimited
    int rr_depth = 3;    // bounces before Russian roulette may end a path
};

class Estimator {
public:
    virtual ~Estimator() = default;
    // One Monte Carlo estimate of the radiance arriving at the camera along `ray`.
    virtual Rgb radiance(const Scene& scene, const Ray& ray, Sampler& sampler) const = 0;
};

struct EstimatorInfo {
    std::string name;                  // e.g. "direct-light"
    std::vector<std::string> aliases;  // the course's assignment numbers, e.g. "1"
    std::string summary;               // one line
    // True when the estimator cannot see delta (point/directional) lights at all, so its image
    // is black in scenes lit only by them (BRDF-sampled estimators).
    bool blind_to_delta_lights = false;
    std::function<std::unique_ptr<Estimator>(const EstimatorOptions&)> make;
};

const std::vector<EstimatorInfo>& estimators();
const EstimatorInfo* find_estimator(const std::string& name_or_alias);
// "a, b (alias 1), ..." for error messages and help.
std::string estimator_names();

}  // namespace pathlab
