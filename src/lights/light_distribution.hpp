// The light-selection distribution: a light is chosen with probability proportional to its
// power (uniformly if all are 0), by the same rule for next-event estimation and light paths;
// or to other weights (light_sampler.hpp's uniform choice of emitters).
#pragma once

#include <algorithm>
#include <numeric>
#include <vector>

#include "lights/light.hpp"

namespace pathlab {

struct LightChoice {
    int index = -1;
    float pmf = 0;  // probability of having chosen this light
};

class LightDistribution {
public:
    LightDistribution() = default;
    LightDistribution(const std::vector<Light>& lights, const SceneSphere& sphere) {
        std::vector<float> power(lights.size());
        for (size_t i = 0; i < lights.size(); ++i) power[i] = std::max(0.0f, light_power(lights[i], sphere));
        *this = LightDistribution(std::move(power));
    }
    // Proportional to the given non-negative weights (uniformly if all are 0).
    explicit LightDistribution(std::vector<float> weights) {
        const size_t n = weights.size();
        pmf_ = std::move(weights);
        const double total = std::accumulate(pmf_.begin(), pmf_.end(), 0.0);
        for (float& p : pmf_) p = total > 0 ? float(p / total) : 1.0f / float(n);
        cdf_.resize(n);
        double running = 0;
        for (size_t i = 0; i < n; ++i) cdf_[i] = float(running += pmf_[i]);
        if (n) cdf_.back() = 1.0f;
    }
    LightChoice choose(float u) const {
        if (cdf_.empty()) return {};
        const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
        const int index = int(std::min<ptrdiff_t>(it - cdf_.begin(), ptrdiff_t(cdf_.size()) - 1));
        return {index, pmf_[size_t(index)]};
    }
    float pmf(int index) const { return pmf_[size_t(index)]; }

private:
    std::vector<float> pmf_, cdf_;
};

}  // namespace pathlab
