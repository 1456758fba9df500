// Axis-aligned boxes in a bounding volume hierarchy, for the queries of a ray segment: every box
// the segment crosses, in an order fixed by the boxes. BallTree (photons as balls) and BeamTree
// (photon beams cut into pieces) are this tree with their own exact tests.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

class BoxTree {
public:
    // Boxes [lo_i, hi_i], split at the medians of their keys (a point per box) along the longest
    // axis of the keys' spread, ties by index: the same tree on every machine.
    void build(const std::vector<Vec3f>& lo, const std::vector<Vec3f>& hi, const std::vector<Vec3f>& keys);

    // f(i) for every box i in a leaf whose node bounds the segment o + s d, s in [0, tmax),
    // crosses (d unit): a superset of the boxes it crosses, for the caller's exact test.
    template <typename F> void for_each_crossed(const Vec3f& o, const Vec3f& d, float tmax, F&& f) const;

    size_t size() const { return order_.size(); }
    size_t memory_bytes() const { return nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(uint32_t); }

private:
    struct Node {
        Vec3f lo, hi;        // the bounds of its boxes
        uint32_t first = 0;  // a leaf: its boxes are order_[first .. first + count); inside: the second child's node
        uint32_t count = 0;  // 0: an inner node, whose first child is the next node
    };
    uint32_t build_node(uint32_t begin, uint32_t end, const std::vector<Vec3f>& lo, const std::vector<Vec3f>& hi,
                        const std::vector<Vec3f>& keys);

    std::vector<Node> nodes_;
    std::vector<uint32_t> order_;
};

template <typename F> void BoxTree::for_each_crossed(const Vec3f& o, const Vec3f& d, float tmax, F&& f) const {
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
        for (uint32_t k = n.first; k < n.first + n.count; ++k) f(order_[k]);
    }
}

}  // namespace pathlab
