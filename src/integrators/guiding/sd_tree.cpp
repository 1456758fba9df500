#include "integrators/guiding/sd_tree.hpp"

#include <algorithm>
#include <cmath>

#include "core/sampling.hpp"

namespace pathlab {

namespace {

constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

int quadrant_of(Vec2f& u) {
    // The quadrant holding u, and u rescaled to that quadrant's own unit square.
    int q = 0;
    if (u.x >= 0.5f) q |= 1, u.x -= 0.5f;
    if (u.y >= 0.5f) q |= 2, u.y -= 0.5f;
    u.x = std::min(2.0f * u.x, kOneMinusEpsilon);
    u.y = std::min(2.0f * u.y, kOneMinusEpsilon);
    return q;
}

// A number in [0, 1) that chose the first of two outcomes of probabilities p and 1 - p,
// stretched back to [0, 1) for reuse.
bool choose_first(float& r, float p) {
    if (r < p) {
        r = std::min(r / p, kOneMinusEpsilon);
        return true;
    }
    r = std::min((r - p) / (1.0f - p), kOneMinusEpsilon);
    return false;
}

}  // namespace

Vec2f direction_to_square(const Vec3f& d) {
    const float cos_theta = std::clamp(d.z, -1.0f, 1.0f);
    float phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2.0f * kPi;
    return {std::clamp((cos_theta + 1.0f) * 0.5f, 0.0f, kOneMinusEpsilon), std::clamp(phi / (2.0f * kPi), 0.0f, kOneMinusEpsilon)};
}

Vec3f square_to_direction(const Vec2f& u) {
    const float cos_theta = 2.0f * u.x - 1.0f;
    const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    const float phi = 2.0f * kPi * u.y;
    return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

QuadTree::QuadTree() : nodes_(1) {}

void QuadTree::record(const Vec2f& point, float value) {
    Vec2f u = point;
    uint32_t node = 0;
    while (true) {
        const int q = quadrant_of(u);
        nodes_[node].sum[size_t(q)] += value;
        if (nodes_[node].child[size_t(q)] == 0) return;
        node = nodes_[node].child[size_t(q)];
    }
}

float QuadTree::pdf(const Vec2f& point) const {
    Vec2f u = point;
    uint32_t node = 0;
    float density = 1.0f;
    while (true) {
        const Node& n = nodes_[node];
        const float total = n.sum[0] + n.sum[1] + n.sum[2] + n.sum[3];
        const int q = quadrant_of(u);
        if (!(total > 0) || !(n.sum[size_t(q)] > 0)) return 0.0f;
        density *= 4.0f * n.sum[size_t(q)] / total;
        if (n.child[size_t(q)] == 0) return density;
        node = n.child[size_t(q)];
    }
}

Vec2f QuadTree::sample(Vec2f r) const {
    r.x = std::min(r.x, kOneMinusEpsilon), r.y = std::min(r.y, kOneMinusEpsilon);
    uint32_t node = 0;
    Vec2f origin(0.0f, 0.0f);
    float size = 1.0f;
    while (true) {
        const Node& n = nodes_[node];
        const auto& s = n.sum;
        const float left = s[0] + s[2], right = s[1] + s[3];
        // The column (x) by its energy, then the row (y) within it: quadrant q with probability s[q] / total.
        const bool is_right = !choose_first(r.x, left + right > 0 ? left / (left + right) : 0.5f);
        const float bottom = is_right ? s[1] : s[0], top = is_right ? s[3] : s[2];
        const bool is_top = !choose_first(r.y, bottom + top > 0 ? bottom / (bottom + top) : 0.5f);
        const int q = int(is_right) | (int(is_top) << 1);
        size *= 0.5f;
        origin.x += is_right ? size : 0.0f;
        origin.y += is_top ? size : 0.0f;
        if (n.child[size_t(q)] == 0) return {std::min(origin.x + r.x * size, kOneMinusEpsilon), std::min(origin.y + r.y * size, kOneMinusEpsilon)};
        node = n.child[size_t(q)];
    }
}

double QuadTree::energy() const {
    const Node& root = nodes_[0];
    return double(root.sum[0]) + double(root.sum[1]) + double(root.sum[2]) + double(root.sum[3]);
}

int QuadTree::depth() const {
    struct Entry {
        uint32_t node;
        int depth;
    };
    std::vector<Entry> stack{{0, 1}};
    int deepest = 1;
    while (!stack.empty()) {
        const Entry e = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, e.depth);
        for (uint32_t c : nodes_[e.node].child)
            if (c) stack.push_back({c, e.depth + 1});
    }
    return deepest;
}

QuadTree QuadTree::refined(float rho, int max_depth) const {
    QuadTree out;
    const double total = energy();
    if (!(total > 0)) return out;
    // A node of the new tree and where its energy comes from: a node of this tree, or (below one
    // of this tree's leaves) an energy spread evenly over the cell.
    struct Entry {
        uint32_t node;
        uint32_t source;  // this tree's node; kSpread: none
        float spread;     // the cell's energy when there is no source node
        int depth;
    };
    constexpr uint32_t kSpread = ~0u;
    std::vector<Entry> stack{{0, 0, 0.0f, 1}};
    while (!stack.empty()) {
        const Entry e = stack.back();
        stack.pop_back();
        for (size_t q = 0; q < 4; ++q) {
            const float energy = e.source == kSpread ? e.spread / 4 : nodes_[e.source].sum[q];
            if (e.depth >= max_depth || !(double(energy) / total > rho)) continue;
            const uint32_t child = uint32_t(out.nodes_.size());
            out.nodes_.emplace_back();
            out.nodes_[e.node].child[q] = child;
            const uint32_t below = e.source == kSpread ? 0 : nodes_[e.source].child[q];
            stack.push_back({child, below ? below : kSpread, energy, e.depth + 1});
        }
    }
    return out;
}

float GuidingLeaf::pdf(const Vec3f& d) const {
    if (!usable) return 0.0f;
    return model == GuidingModel::kVmm ? mixture.pdf(d) : sampling.pdf(direction_to_square(d)) * (1.0f / (4.0f * kPi));
}

Vec3f GuidingLeaf::sample(Vec2f r) const { return model == GuidingModel::kVmm ? mixture.sample(r) : square_to_direction(sampling.sample(r)); }

SdTree::SdTree(const Vec3f& center, float radius, GuidingModel model) {
    leaves_[0].model = model;
    const float r = radius > 0 && std::isfinite(radius) ? radius : 1.0f;
    min_ = center - Vec3f(r);
    size_ = 2.0f * r;
}

size_t SdTree::leaf_index(const Vec3f& p) const {
    Vec3f u = (p - min_) / size_;
    for (int a = 0; a < 3; ++a) u[a] = std::clamp(u[a], 0.0f, kOneMinusEpsilon);
    uint32_t node = 0;
    while (nodes_[node].child[0] != 0) {
        const Node& n = nodes_[node];
        float& x = u[n.axis];
        const bool upper = x >= 0.5f;
        x = std::min(upper ? 2.0f * x - 1.0f : 2.0f * x, kOneMinusEpsilon);
        node = n.child[upper ? 1 : 0];
    }
    return nodes_[node].leaf;
}

void SdTree::record(const Vec3f& p, const Vec3f& direction, float value) {
    GuidingLeaf& l = leaf(p);
    ++l.records;
    if (!(value > 0) || !std::isfinite(value)) return;
    if (l.model == GuidingModel::kVmm)
        l.fit.add(direction, value);
    else
        l.building.record(direction_to_square(direction), value);
}

void SdTree::record_outgoing(const Vec3f& p, float radiance) {
    if (!(radiance >= 0) || !std::isfinite(radiance)) return;
    GuidingLeaf& l = leaf(p);
    l.outgoing_sum += radiance;
    ++l.outgoing_count;
}

void BsdfFractionFit::step(float gradient) {
    if (!std::isfinite(gradient)) return;
    constexpr float kBeta1 = 0.9f, kBeta2 = 0.999f, kEpsilon = 1e-8f;
    const float g = gradient + kRegularisation * theta;
    // (to 0 once they no longer matter, rather than through the slow denormal floats)
    beta1_t = beta1_t > 1e-20f ? beta1_t * kBeta1 : 0.0f, beta2_t = beta2_t > 1e-20f ? beta2_t * kBeta2 : 0.0f;
    m = kBeta1 * m + (1 - kBeta1) * g;
    v = kBeta2 * v + (1 - kBeta2) * g * g;
    const float m_hat = m / (1 - beta1_t), v_hat = v / (1 - beta2_t);
    theta = std::clamp(theta - kLearningRate * m_hat / (std::sqrt(v_hat) + kEpsilon), -kMaxTheta, kMaxTheta);
    a = 1.0f / (1.0f + std::exp(-theta));
}

void SdTree::record_fraction_gradient(const Vec3f& p, float gradient) { leaf(p).fraction.step(gradient); }

void SdTree::split(uint32_t node) {
    const uint32_t leaf = nodes_[node].leaf;
    const uint8_t axis = uint8_t((nodes_[node].axis + 1) % 3);
    leaves_[leaf].records /= 2;
    leaves_.push_back(leaves_[leaf]);
    const uint32_t first = uint32_t(nodes_.size());
    nodes_.push_back(Node{{0, 0}, leaf, axis});
    nodes_.push_back(Node{{0, 0}, uint32_t(leaves_.size() - 1), axis});
    nodes_[node].child[0] = first, nodes_[node].child[1] = first + 1;
}

void SdTree::refine(uint64_t iteration_spp) {
    const double threshold = kSplitConstant * std::sqrt(double(std::max<uint64_t>(1, iteration_spp)));
    // Children are appended, so the loop visits them too (a split halves the counts).
    for (uint32_t node = 0; node < nodes_.size(); ++node)
        if (nodes_[node].child[0] == 0 && double(leaves_[nodes_[node].leaf].records) > threshold) split(node);
    for (GuidingLeaf& l : leaves_) {
        if (l.model == GuidingModel::kVmm) {
            l.fit.flush();
            l.mixture = l.fit.mixture();
            l.usable = l.fit.directions() > 0;
        } else {
            l.sampling = std::move(l.building);
            l.usable = l.sampling.energy() > 0;
            l.building = l.sampling.refined(kEnergyFraction, kMaxQuadDepth);
        }
        l.records = 0;
        l.outgoing = l.outgoing_count ? float(l.outgoing_sum / double(l.outgoing_count)) : 0.0f;
        l.outgoing_sum = 0, l.outgoing_count = 0;
    }
}

size_t SdTree::spatial_depth() const {
    std::vector<std::pair<uint32_t, size_t>> stack{{0, 1}};
    size_t deepest = 1;
    while (!stack.empty()) {
        const auto [node, depth] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, depth);
        if (nodes_[node].child[0] != 0)
            for (uint32_t c : nodes_[node].child) stack.push_back({c, depth + 1});
    }
    return deepest;
}

size_t SdTree::memory_bytes() const {
    size_t bytes = nodes_.capacity() * sizeof(Node) + leaves_.capacity() * sizeof(GuidingLeaf);
    for (const GuidingLeaf& l : leaves_) bytes += l.sampling.memory_bytes() + l.building.memory_bytes();
    return bytes;
}

}  // namespace pathlab
