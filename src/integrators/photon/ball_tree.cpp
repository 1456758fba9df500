#include "integrators/photon/ball_tree.hpp"

#include <cmath>

namespace pathlab {

void BallTree::build(Positions centres, const std::vector<float>& radii) {
    const size_t n = centres.size();
    centre_.resize(n), radius2_.resize(n);
    std::vector<Vec3f> lo(n), hi(n);
    for (size_t i = 0; i < n; ++i) {
        centre_[i] = centres[i], radius2_[i] = radii[i] * radii[i];
        const float r = std::sqrt(radius2_[i]);
        lo[i] = centre_[i] - Vec3f(r), hi[i] = centre_[i] + Vec3f(r);
    }
    tree_.build(lo, hi, centre_);  // split at the centres' medians
}

}  // namespace pathlab
