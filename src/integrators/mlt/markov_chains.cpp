#include "integrators/mlt/markov_chains.hpp"

#include <cmath>

namespace pathlab {

double mlt_contribution(const Vec3d& c) {
    return 0.2126 * std::abs(c.x) + 0.7152 * std::abs(c.y) + 0.0722 * std::abs(c.z);
}

}  // namespace pathlab
