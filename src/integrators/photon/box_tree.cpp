#include "integrators/photon/box_tree.hpp"

#include <algorithm>

namespace pathlab {
namespace {
constexpr uint32_t kLeafSize = 4;
}

void BoxTree::build(const std::vector<Vec3f>& lo, const std::vector<Vec3f>& hi, const std::vector<Vec3f>& keys) {
    const size_t n = lo.size();
    order_.resize(n);
    for (size_t i = 0; i < n; ++i) order_[i] = uint32_t(i);
    nodes_.clear();
    if (n == 0) return;
    nodes_.reserve(n);  // median splits leave at least 2 boxes in a leaf: at most n / 2 leaves, n nodes
    build_node(0, uint32_t(n), lo, hi, keys);
}

// Median splits: depth about log2(n / 4), far below the traversal's stack of 64.
uint32_t BoxTree::build_node(uint32_t begin, uint32_t end, const std::vector<Vec3f>& lo, const std::vector<Vec3f>& hi,
                             const std::vector<Vec3f>& keys) {
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.emplace_back();
    Vec3f blo(kInf), bhi(-kInf), klo(kInf), khi(-kInf);
    for (uint32_t k = begin; k < end; ++k) {
        const uint32_t i = order_[k];
        blo = min(blo, lo[i]), bhi = max(bhi, hi[i]);
        klo = min(klo, keys[i]), khi = max(khi, keys[i]);
    }
    nodes_[index].lo = blo, nodes_[index].hi = bhi;
    const Vec3f extent = khi - klo;
    if (end - begin <= kLeafSize || !(max_component(extent) > 0)) {
        nodes_[index].first = begin, nodes_[index].count = end - begin;
        return index;
    }
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](uint32_t a, uint32_t b) {
        return keys[a][axis] < keys[b][axis] || (keys[a][axis] == keys[b][axis] && a < b);
    });
    build_node(begin, mid, lo, hi, keys);
    const uint32_t second = build_node(mid, end, lo, hi, keys);
    nodes_[index].first = second;
    nodes_[index].count = 0;
    return index;
}

}  // namespace pathlab
