// Balls, each of its own radius, in a bounding volume hierarchy for the query of a beam: every
// ball whose centre lies within its radius of a ray segment. pm's beam radiance estimate (Jarosz,
// Zwicker and Jensen 2008) gives each photon in a medium the radius of its k nearest neighbours
// and sums the photons whose balls a camera ray passes through; the photon grid cannot serve
// radii that differ by orders of magnitude (dense near a volumetric caustic, sparse elsewhere).
// upbp's point-beam estimator queries balls of one radius.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "integrators/photon/box_tree.hpp"
#include "integrators/photon/photon_grid.hpp"

namespace pathlab {

class BallTree {
public:
    // Balls around the items' positions with the given radii (as many). The tree keeps its own copy.
    void build(Positions centres, const std::vector<float>& radii);

    // f(i, s) for every ball i whose centre c projects onto o + s d with s in [0, tmax) and lies
    // within the ball's radius of the ray (d unit), in an order fixed by the balls: results do
    // not depend on threads.
    template <typename F> void for_each_along(const Vec3f& o, const Vec3f& d, float tmax, F&& f) const {
        tree_.for_each_crossed(o, d, tmax, [&](uint32_t i) {
            const Vec3f oc = centre_[i] - o;
            const float s = dot(oc, d);
            if (s >= 0 && s < tmax && dot(oc, oc) - s * s <= radius2_[i]) f(i, s);
        });
    }

    float radius2(size_t i) const { return radius2_[i]; }
    size_t size() const { return centre_.size(); }
    size_t memory_bytes() const {
        return tree_.memory_bytes() + centre_.capacity() * sizeof(Vec3f) + radius2_.capacity() * sizeof(float);
    }

private:
    BoxTree tree_;
    std::vector<Vec3f> centre_;
    std::vector<float> radius2_;
};

}  // namespace pathlab
