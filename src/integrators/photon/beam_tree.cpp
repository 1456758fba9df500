#include "integrators/photon/beam_tree.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {

void BeamTree::build(const std::vector<Segment>& segments, float r, float piece) {
    pieces_.clear();
    std::vector<Vec3f> lo, hi, centres;
    for (size_t i = 0; i < segments.size(); ++i) {
        const Segment& s = segments[i];
        const int n = std::max(1, int(std::ceil(s.length / piece)));
        for (int k = 0; k < n; ++k) {
            const float t0 = s.length * float(k) / float(n), t1 = k + 1 == n ? s.length : s.length * float(k + 1) / float(n);
            const Vec3f a = s.o + s.d * t0, b = s.o + s.d * t1;
            pieces_.push_back({uint32_t(i), t0, t1});
            lo.push_back(min(a, b) - Vec3f(r)), hi.push_back(max(a, b) + Vec3f(r));
            centres.push_back((a + b) * 0.5f);
        }
    }
    tree_.build(lo, hi, centres);
}

}  // namespace pathlab
