#include "integrators/photon/photon_grid.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <nanoflann.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace pathlab {

void PhotonGrid::sort_into_cells(Positions photons, float radius) {
    positions_ = photons;
    sorted_ = false;
    const size_t n = photons.size();
    // A little over 2r, so that a ball of radius r around a query is within the 2 x 2 x 2 cells
    // it visits even after rounding.
    cell_size_ = 2 * radius * 1.0001f;
    inv_cell_ = 1 / cell_size_;
    constexpr size_t kGrain = 4096;
    lo_ = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, kGrain), Vec3f(kInf),
        [&](const tbb::blocked_range<size_t>& range, Vec3f lo) {
            for (size_t i = range.begin(); i != range.end(); ++i) lo = min(lo, photons[i]);
            return lo;
        },
        [](const Vec3f& a, const Vec3f& b) { return min(a, b); });  // exact: any grouping gives the same
    if (n == 0) lo_ = Vec3f(0.0f);
    // As many table cells as photons (at least 1): short lists, few collisions. Each photon's
    // cell, and the cells' counts (a count does not depend on the order of the increments).
    cell_ends_.assign(std::max<size_t>(1, n), 0);
    place_.resize(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const Vec3f c = (photons[i] - lo_) * inv_cell_;
            place_[i] = uint32_t(cell_index(int(std::floor(c.x)), int(std::floor(c.y)), int(std::floor(c.z))));
            std::atomic_ref<uint32_t>(cell_ends_[place_[i]]).fetch_add(1, std::memory_order_relaxed);
        }
    });
    // Counting sort: cell_ends_[c] becomes the end of cell c's run; photons keep their order
    // within a cell, and place_ turns from each photon's cell into its slot.
    uint32_t sum = 0;
    for (uint32_t& e : cell_ends_) sum += e, e = sum;
    for (size_t i = n; i-- > 0;) place_[i] = --cell_ends_[place_[i]];
    for (size_t c = 0; c + 1 < cell_ends_.size(); ++c) cell_ends_[c] = cell_ends_[c + 1];
    cell_ends_.back() = uint32_t(n);
}

void PhotonGrid::build(Positions photons, float radius) {
    sort_into_cells(photons, radius);
    order_.resize(photons.size());
    tbb::parallel_for(size_t(0), photons.size(), [&](size_t i) { order_[place_[i]] = uint32_t(i); });
}

const std::vector<uint32_t>& PhotonGrid::build_placed(Positions photons, float radius) {
    sort_into_cells(photons, radius);
    sorted_p_.resize(photons.size());
    tbb::parallel_for(size_t(0), photons.size(), [&](size_t i) { sorted_p_[place_[i]] = photons[i]; });
    positions_ = Positions::of(sorted_p_);
    sorted_ = true;
    return place_;
}

namespace {

// nanoflann's view of the items.
struct PhotonCloud {
    Positions positions;
    size_t kdtree_get_point_count() const { return positions.size(); }
    float kdtree_get_pt(size_t i, size_t dim) const { return positions[i][int(dim)]; }
    template <class BBox> bool kdtree_get_bbox(BBox&) const { return false; }
};

using KdIndex = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PhotonCloud>, PhotonCloud, 3, uint32_t>;

// Collects indices within r^2 (nanoflann's ResultSet concept), without allocating beyond `out`.
struct Collector {
    float r2;
    std::vector<uint32_t>& out;
    void init() { out.clear(); }
    size_t size() const { return out.size(); }
    bool full() const { return true; }
    bool addPoint(float dist2, uint32_t index) {
        if (dist2 <= r2) out.push_back(index);
        return true;
    }
    // nanoflann adds only points closer than this: one ulp beyond r^2, so that r^2 itself counts.
    float worstDist() const { return std::nextafter(r2, kInf); }
};

}  // namespace

struct PhotonKdTree::Index {
    PhotonCloud cloud;
    KdIndex tree;
    explicit Index(Positions positions)
        : cloud{positions}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
        tree.buildIndex();
    }
};

PhotonKdTree::PhotonKdTree() = default;
PhotonKdTree::~PhotonKdTree() = default;

void PhotonKdTree::build(Positions positions, float) { index_ = std::make_unique<Index>(positions); }

void PhotonKdTree::within(const Vec3f& q, float r, std::vector<uint32_t>& out) const {
    out.clear();
    if (!index_ || index_->cloud.positions.empty()) return;
    Collector c{r * r, out};
    const float query[3] = {q.x, q.y, q.z};
    nanoflann::SearchParams params;
    params.sorted = false;
    index_->tree.findNeighbors(c, query, params);
    std::sort(out.begin(), out.end());
}

size_t PhotonKdTree::nearest(const Vec3f& q, size_t k, uint32_t* indices, float* dist2) const {
    if (!index_ || index_->cloud.positions.empty()) return 0;
    const float query[3] = {q.x, q.y, q.z};
    return index_->tree.knnSearch(query, k, indices, dist2);
}

}  // namespace pathlab
