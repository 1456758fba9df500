#include "integrators/photon/ball_tree.hpp"

#include <algorithm>
#include <cmath>

namespace pathlab {
namespace {
constexpr uint32_t kLeafSize = 4;
}

void BallTree::build(Positions centres, const std::vector<float>& radii) {
    const size_t n = centres.size();
    centre_.resize(n), radius2_.resize(n), order_.resize(n);
    for (size_t i = 0; i < n; ++i) centre_[i] = centres[i], radius2_[i] = radii[i] * radii[i], order_[i] = uint32_t(i);
    nodes_.clear();
    if (n == 0) return;
    nodes_.reserve(n);  // median splits leave at least 2 balls in a leaf: at most n / 2 leaves, n nodes
    build_node(0, uint32_t(n));
}

// Median splits along the longest axis of the centres' bounds: depth about log2(n / 4), far
// below the traversal's stack of 64.
uint32_t BallTree::build_node(uint32_t begin, uint32_t end) {
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.emplace_back();
    Vec3f lo(kInf), hi(-kInf), clo(kInf), chi(-kInf);
    for (uint32_t k = begin; k < end; ++k) {
        const uint32_t i = order_[k];
        const float r = std::sqrt(radius2_[i]);
        lo = min(lo, centre_[i] - Vec3f(r)), hi = max(hi, centre_[i] + Vec3f(r));
        clo = min(clo, centre_[i]), chi = max(chi, centre_[i]);
    }
    nodes_[index].lo = lo, nodes_[index].hi = hi;
    const Vec3f extent = chi - clo;
    if (end - begin <= kLeafSize || !(max_component(extent) > 0)) {
        nodes_[index].first = begin, nodes_[index].count = end - begin;
        return index;
    }
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const uint32_t mid = begin + (end - begin) / 2;
    // Ties broken by index: the same tree on every machine.
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](uint32_t a, uint32_t b) {
        return centre_[a][axis] < centre_[b][axis] || (centre_[a][axis] == centre_[b][axis] && a < b);
    });
    build_node(begin, mid);
    const uint32_t second = build_node(mid, end);
    nodes_[index].first = second;
    nodes_[index].count = 0;
    return index;
}

}  // namespace pathlab
