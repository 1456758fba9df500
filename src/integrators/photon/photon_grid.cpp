#include "integrators/photon/photon_grid.hpp"

#include <algorithm>
#include <cmath>

#include <nanoflann.hpp>

namespace pathlab {

void PhotonGrid::build(Positions photons, float radius) {
    positions_ = photons;
    sorted_ = false;
    // A little over 2r, so that a ball of radius r around a query is within the 2 x 2 x 2 cells
    // it visits even after rounding.
    cell_size_ = 2 * radius * 1.0001f;
    inv_cell_ = 1 / cell_size_;
    lo_ = Vec3f(kInf);
    for (size_t i = 0; i < photons.size(); ++i) lo_ = min(lo_, photons[i]);
    if (photons.empty()) lo_ = Vec3f(0.0f);
    // As many table cells as photons (at least 1): short lists, few collisions.
    cell_ends_.assign(std::max<size_t>(1, photons.size()), 0);
    cell_of_.resize(photons.size());
    for (size_t i = 0; i < photons.size(); ++i) {
        const Vec3f c = (photons[i] - lo_) * inv_cell_;
        cell_of_[i] = uint32_t(cell_index(int(std::floor(c.x)), int(std::floor(c.y)), int(std::floor(c.z))));
        ++cell_ends_[cell_of_[i]];
    }
    // Counting sort: cell_ends_[c] becomes the end of cell c's run; photons keep their order.
    uint32_t sum = 0;
    for (uint32_t& e : cell_ends_) sum += e, e = sum;
    order_.resize(photons.size());
    for (size_t i = photons.size(); i-- > 0;) order_[--cell_ends_[cell_of_[i]]] = uint32_t(i);
    for (size_t c = 0; c + 1 < cell_ends_.size(); ++c) cell_ends_[c] = cell_ends_[c + 1];
    cell_ends_.back() = uint32_t(photons.size());
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
