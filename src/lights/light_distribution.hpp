// The light-selection distribution: a light is chosen with probability proportional to its
// power (uniformly if all are 0), by the same rule for next-event estimation and light paths.
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
        const size_t n = lights.size();
        pmf_.resize(n);
        for (size_t i = 0; i < n; ++i) pmf_[i] = std::max(0.0f, light_power(lights[i], sphere));
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
