// Range search over photons, two ways (issue: measure both and keep the faster, see README):
//   PhotonGrid    a hashed uniform grid of cells 2r wide (as SmallVCM's HashGrid): photons
//                 sorted by cell with a counting sort; a query visits the 2 x 2 x 2 cells its
//                 ball can touch;
//   PhotonKdTree  nanoflann's k-d tree (a maintained library), radius search with a callback.
// Both search any array of items with a position `p` (photons of either transport, surfel
// centres), without a copy of it, and call f(i) for exactly the indices i of the items within
// distance r of q (|p - q|^2 <= r^2), in an order fixed by the items' order: results do not
// depend on threads.
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include "core/vec.hpp"

namespace pathlab {

// Where the positions of n items lie in memory: the first one's, and the distance between two.
struct Positions {
    const char* first = nullptr;
    size_t stride = 0, count = 0;

    template <class P> static Positions of(const std::vector<P>& items) {
        return {items.empty() ? nullptr : reinterpret_cast<const char*>(&items.front().p), sizeof(P), items.size()};
    }
    static Positions of(const std::vector<Vec3f>& points) {
        return {points.empty() ? nullptr : reinterpret_cast<const char*>(points.data()), sizeof(Vec3f), points.size()};
    }
    const Vec3f& operator[](size_t i) const { return *reinterpret_cast<const Vec3f*>(first + i * stride); }
    size_t size() const { return count; }
    bool empty() const { return count == 0; }
};

// Asks for the cache lines of an item ahead of its use (for_each_within's prefetch).
template <class P> inline void prefetch_item(const P& item) {
    const char* first = reinterpret_cast<const char*>(&item);
    __builtin_prefetch(first);
    __builtin_prefetch(first + sizeof(P) - 1);
}

class PhotonGrid {
public:
    // `radius`: the largest query radius to come. The items must stay where they are while the
    // grid is searched.
    template <class P> void build(const std::vector<P>& items, float radius) { build(Positions::of(items), radius); }
    void build(Positions positions, float radius);
    // For items that the caller stores in the grid's cell order itself (vcm writes each merge
    // vertex once, at its place, instead of moving a million of them after the build): returns
    // place, where place[i] is the slot in that order of the item at positions[i] (stable: by
    // index within a cell). The grid keeps a dense copy of the positions in that order, so a
    // query's distance tests read one contiguous run of 12-byte positions per cell, and f(k) gets
    // slots. `positions` need not outlive the call. Parallel; the same result on any number of threads.
    const std::vector<uint32_t>& build_placed(Positions positions, float radius);
    template <typename F> void for_each_within(const Vec3f& q, float r, F&& f) const { for_each_within(q, r, f, [](uint32_t) {}); }
    // The same, calling prefetch(i) for the items found ahead of f(i): they are gathered in
    // batches, all of a batch's prefetches issued before its first f, so that the reads of their
    // records (random, each a cache miss once the photons outgrow the caches) overlap instead of
    // each waiting for f to finish the one before. f still sees the items in the same order.
    template <typename F, typename Prefetch> void for_each_within(const Vec3f& q, float r, F&& f, Prefetch&& prefetch) const;
    size_t memory_bytes() const {
        return cell_ends_.capacity() * sizeof(uint32_t) + order_.capacity() * sizeof(uint32_t) + place_.capacity() * sizeof(uint32_t) +
               sorted_p_.capacity() * sizeof(Vec3f);
    }

private:
    size_t cell_index(int x, int y, int z) const {
        return size_t((uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ (uint32_t(z) * 83492791u)) % cell_ends_.size();
    }
    Positions positions_;
    Vec3f lo_{0.0f};
    float cell_size_ = 1, inv_cell_ = 1;
    std::vector<uint32_t> cell_ends_;  // cell c: slots cell_ends_[c-1] .. cell_ends_[c] of the cell order
    std::vector<uint32_t> order_;      // build: photon indices sorted by cell (stable: by index within a cell)
    std::vector<uint32_t> place_;      // each photon's slot in that order (order_'s inverse)
    bool sorted_ = false;              // build_placed: positions_ is sorted_p_, in cell order; order_ is unused
    std::vector<Vec3f> sorted_p_;      // build_placed: the items' positions, in cell order
    // Both builds: the cells' runs (cell_ends_) and each item's slot (place_).
    void sort_into_cells(Positions positions, float radius);
};

template <typename F, typename Prefetch> void PhotonGrid::for_each_within(const Vec3f& q, float r, F&& f, Prefetch&& prefetch) const {
    if (positions_.empty()) return;
    const float r2 = r * r;
    // The cell holding q, and the neighbours on the side of q's position within it.
    const Vec3f c = (q - lo_) * inv_cell_;
    const int cx = int(std::floor(c.x)), cy = int(std::floor(c.y)), cz = int(std::floor(c.z));
    const int px = c.x - float(cx) < 0.5f ? cx - 1 : cx, py = c.y - float(cy) < 0.5f ? cy - 1 : cy,
              pz = c.z - float(cz) < 0.5f ? cz - 1 : cz;
    // Two grid cells may hash to one table cell: visit each table cell once. The cells' runs are
    // looked up first, and then scanned: the lookups (random reads of the table, the query's
    // main cost once the photons outgrow the caches) are then independent and overlap.
    size_t visited[8];
    uint32_t begins[8], ends[8];
    int n_visited = 0;
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const size_t cell = cell_index(px + dx, py + dy, pz + dz);
                bool seen = false;
                for (int k = 0; k < n_visited; ++k) seen |= visited[k] == cell;
                if (!seen) visited[n_visited++] = cell;
            }
    for (int k = 0; k < n_visited; ++k) {
        begins[k] = visited[k] == 0 ? 0 : cell_ends_[visited[k] - 1];
        ends[k] = cell_ends_[visited[k]];
    }
    for (int k = 0; k < n_visited; ++k)
        if (begins[k] < ends[k]) __builtin_prefetch(&positions_[sorted_ ? begins[k] : order_[begins[k]]]);
    constexpr int kBatch = 16;
    uint32_t batch[kBatch];
    int n = 0;
    for (int c = 0; c < n_visited; ++c)
        for (uint32_t k = begins[c]; k < ends[c]; ++k) {
            const uint32_t i = sorted_ ? k : order_[k];
            const Vec3f d = positions_[i] - q;
            if (dot(d, d) <= r2) {
                prefetch(i);
                batch[n++] = i;
                if (n == kBatch) {
                    for (int j = 0; j < n; ++j) f(batch[j]);
                    n = 0;
                }
            }
        }
    for (int j = 0; j < n; ++j) f(batch[j]);
}

class PhotonKdTree {
public:
    PhotonKdTree();
    ~PhotonKdTree();
    template <class P> void build(const std::vector<P>& items, float radius) { build(Positions::of(items), radius); }
    void build(Positions positions, float radius);
    template <typename F> void for_each_within(const Vec3f& q, float r, F&& f) const;

    // The k items nearest to q (fewer if there are fewer), nearest first: their indices and
    // squared distances into indices[0..k) and dist2[0..k); returns how many were found.
    size_t nearest(const Vec3f& q, size_t k, uint32_t* indices, float* dist2) const;

    struct Index;  // nanoflann's, in photon_grid.cpp

private:
    // Calls back with indices (nanoflann's own order), which this sorts.
    void within(const Vec3f& q, float r, std::vector<uint32_t>& out) const;
    std::unique_ptr<Index> index_;
};

template <typename F> void PhotonKdTree::for_each_within(const Vec3f& q, float r, F&& f) const {
    thread_local std::vector<uint32_t> found;
    within(q, r, found);
    for (const uint32_t i : found) f(i);
}

}  // namespace pathlab
