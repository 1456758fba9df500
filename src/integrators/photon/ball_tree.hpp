// Balls, each of its own radius, in a bounding volume hierarchy for the query of a beam: every
// ball whose centre lies within its radius of a ray segment. pm's beam radiance estimate (Jarosz,
// Zwicker and Jensen 2008) gives each photon in a medium the radius of its k nearest neighbours
// and sums the photons whose balls a camera ray passes through; the photon grid cannot serve
// radii that differ by orders of magnitude (dense near a volumetric caustic, sparse elsewhere).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "integrators/photon/photon_grid.hpp"

namespace pathlab {

class BallTree {
public:
    // Balls around the items' positions with the given radii (as many). The tree keeps its own copy.
    void build(Positions centres, const std::vector<float>& radii);

    // f(i, s) for every ball i whose centre c projects onto o + s d with s in [0, tmax) and lies
    // within the ball's radius of the ray (d unit), in an order fixed by the balls: results do
    // not depend on threads.
    template <typename F> void for_each_along(const Vec3f& o, const Vec3f& d, float tmax, F&& f) const;

    float radius2(size_t i) const { return radius2_[i]; }
    size_t size() const { return centre_.size(); }
    size_t memory_bytes() const {
        return nodes_.capacity() * sizeof(Node) + centre_.capacity() * sizeof(Vec3f) + radius2_.capacity() * sizeof(float) +
               order_.capacity() * sizeof(uint32_t);
    }

private:
    struct Node {
        Vec3f lo, hi;       // the bounds of its balls
        uint32_t first = 0;  // a leaf: its balls are order_[first .. first + count); inside: the second child's node
        uint32_t count = 0;  // 0: an inner node, whose first child is the next node
    };
    uint32_t build_node(uint32_t begin, uint32_t end);

    std::vector<Node> nodes_;
    std::vector<Vec3f> centre_;
    std::vector<float> radius2_;
    std::vector<uint32_t> order_;
};

template <typename F> void BallTree::for_each_along(const Vec3f& o, const Vec3f& d, float tmax, F&& f) const {
    if (nodes_.empty()) return;
    const Vec3f inv(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = nodes_[stack[--top]];
        // The slab test of the segment against the node's bounds (a direction parallel to a slab
        // gives infinities that compare as they should; NaN, its origin on the slab's plane,
        // compares false: no constraint).
        float t0 = 0, t1 = tmax;
        for (int a = 0; a < 3; ++a) {
            float ta = (n.lo[a] - o[a]) * inv[a], tb = (n.hi[a] - o[a]) * inv[a];
            if (ta > tb) std::swap(ta, tb);
            if (ta > t0) t0 = ta;
            if (tb < t1) t1 = tb;
        }
        if (t0 > t1) continue;
        if (n.count == 0) {
            // Second child below the first: the first is visited first.
            stack[top++] = n.first;
            stack[top++] = uint32_t(&n - nodes_.data()) + 1;
            continue;
        }
        for (uint32_t k = n.first; k < n.first + n.count; ++k) {
            const uint32_t i = order_[k];
            const Vec3f oc = centre_[i] - o;
            const float s = dot(oc, d);
            if (s >= 0 && s < tmax && dot(oc, oc) - s * s <= radius2_[i]) f(i, s);
        }
    }
}

}  // namespace pathlab
