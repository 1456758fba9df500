#include "lights/light_sampler.hpp"

#include <algorithm>
#include <array>
#include <map>

namespace pathlab {

const char* light_sampler_name(LightSamplerKind kind) {
    switch (kind) {
        case LightSamplerKind::Uniform: return "uniform";
        case LightSamplerKind::Power: return "power";
        case LightSamplerKind::Bvh: return "bvh";
        case LightSamplerKind::Ris: return "ris";
    }
    return "power";
}

std::optional<LightSamplerKind> parse_light_sampler(const std::string& name) {
    for (const LightSamplerKind k : {LightSamplerKind::Uniform, LightSamplerKind::Power, LightSamplerKind::Bvh, LightSamplerKind::Ris})
        if (name == light_sampler_name(k)) return k;
    return std::nullopt;
}

namespace {

template <class Node> void set_sphere(Node& node, const LightBounds& b) {
    node.centre[0] = b.centre.x, node.centre[1] = b.centre.y, node.centre[2] = b.centre.z;
    node.radius = b.radius;
}

// The solid angle a group's emission can reach, M_Omega of Conty Estevez and Kulla (the
// orientation factor of the surface area orientation heuristic that splits the tree).
float orientation_measure(const LightBounds& b) {
    const float theta_w = std::min(b.theta_o + b.theta_e, kPi);
    return 2 * kPi * (1 - b.cos_o) +
           kPi / 2 * (2 * theta_w * b.sin_o - std::cos(b.theta_o - 2 * theta_w) - 2 * b.theta_o * b.sin_o + b.cos_o);
}

float surface_area(const LightBounds& b) {
    const Vec3f d = max(b.hi - b.lo, Vec3f(0.0f));
    return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// The cost of a group: its power, the solid angle of its emission and its size.
float split_cost(const LightBounds& b) {
    if (!(b.phi > 0)) return 0.0f;
    return b.phi * orientation_measure(b) * std::max(surface_area(b), 1e-12f);
}

}  // namespace

LightSampler::LightSampler(const std::vector<Light>& lights, const SceneSphere& sphere, LightSamplerKind kind, int candidates,
                           const std::vector<int>& emitter_of, float split)
    : kind_(kind), count_(int(lights.size())), candidates_(kind == LightSamplerKind::Ris ? candidates : 1),
      split_(kind == LightSamplerKind::Bvh ? split : 0.0f) {
    if (kind_ == LightSamplerKind::Power) power_ = LightDistribution(lights, sphere);
    if (kind_ == LightSamplerKind::Uniform) {
        // 1 / (the number of emitters) each, shared among an emitter's lights by their areas.
        const auto emitter = [&](size_t i) { return emitter_of.empty() ? int(i) : emitter_of[i]; };
        const auto area = [&](size_t i) {
            const auto* t = std::get_if<TriangleLight>(&lights[i]);
            return t ? double(t->area) : 1.0;
        };
        std::map<int, double> emitter_area;
        for (size_t i = 0; i < lights.size(); ++i) emitter_area[emitter(i)] += area(i);
        std::vector<float> weights(lights.size());
        for (size_t i = 0; i < lights.size(); ++i) {
            const double total = emitter_area[emitter(i)];
            weights[i] = total > 0 ? float(area(i) / total) : 0.0f;
        }
        uniform_ = LightDistribution(std::move(weights));
    }
    if (kind_ != LightSamplerKind::Bvh && kind_ != LightSamplerKind::Ris) return;
    std::vector<Item> items;
    trails_.assign(lights.size(), {});
    for (size_t i = 0; i < lights.size(); ++i) {
        if (light_flags(lights[i]) & kLightInfinite) infinite_.push_back(int(i));
        else items.push_back({light_bounds(lights[i], sphere), int(i)});
    }
    if (items.empty()) return;
    std::vector<BinaryNode> binary;
    binary.reserve(2 * items.size() - 1);
    build_binary(binary, items, 0, items.size(), 0);
    if (binary[0].light >= 0) {  // a single light: a root with one lane
        nodes_.emplace_back();
        nodes_[0].bounds.set(0, binary[0].bounds);
        nodes_[0].child[0] = ~binary[0].light;
        trails_[size_t(binary[0].light)] = {0, 1};
        set_sphere(nodes_[0], binary[0].bounds);
    } else {
        collapse(binary, 0, 0, 0);
    }
}

int LightSampler::build_binary(std::vector<BinaryNode>& out, std::vector<Item>& items, size_t begin, size_t end, int depth) {
    const int index = int(out.size());
    out.emplace_back();
    LightBounds all;
    Vec3f clo(kInf), chi(-kInf);
    for (size_t i = begin; i < end; ++i) {
        all = unite(all, items[i].bounds);
        const Vec3f c = items[i].bounds.centre;
        clo = min(clo, c), chi = max(chi, c);
    }
    out[size_t(index)].bounds = all;
    if (end - begin == 1) {
        out[size_t(index)].light = items[begin].light;
        return index;
    }
    // The split: binned surface area orientation heuristic over the centroids (12 buckets per
    // axis, each axis's cost scaled by how thin the node is along it); by count at the
    // median when the centroids coincide, and below depth 32, so that the binary tree is at most
    // 64 deep (32 levels of the 4-wide one: a trail of 64 bits).
    constexpr int kBuckets = 12;
    size_t mid = begin + (end - begin) / 2;
    const Vec3f extent = chi - clo;
    const auto bucket_of = [&](const Item& item, int axis) {
        return std::clamp(int(float(kBuckets) * (item.bounds.centre[axis] - clo[axis]) / extent[axis]), 0, kBuckets - 1);
    };
    const float longest = max_component(extent);
    int best_axis = -1;
    float best_plane = 0, best_cost = kInf;
    if (depth < 32)
        for (int axis = 0; axis < 3; ++axis) {
            if (!(extent[axis] > 0)) continue;
            std::array<LightBounds, kBuckets> bucket{};
            std::array<size_t, kBuckets> count{};
            for (size_t i = begin; i < end; ++i) {
                const int k = bucket_of(items[i], axis);
                bucket[size_t(k)] = unite(bucket[size_t(k)], items[i].bounds);
                ++count[size_t(k)];
            }
            const float thinness = longest / extent[axis];
            for (int plane = 1; plane < kBuckets; ++plane) {
                LightBounds left, right;
                size_t nl = 0, nr = 0;
                for (int k = 0; k < plane; ++k) left = unite(left, bucket[size_t(k)]), nl += count[size_t(k)];
                for (int k = plane; k < kBuckets; ++k) right = unite(right, bucket[size_t(k)]), nr += count[size_t(k)];
                if (nl == 0 || nr == 0) continue;
                const float cost = thinness * (split_cost(left) + split_cost(right));
                if (cost < best_cost) best_cost = cost, best_axis = axis, best_plane = float(plane);
            }
        }
    if (best_axis >= 0) {
        const int axis = best_axis;
        const auto it = std::partition(items.begin() + ptrdiff_t(begin), items.begin() + ptrdiff_t(end),
                                       [&](const Item& item) { return float(bucket_of(item, axis)) < best_plane; });
        mid = size_t(it - items.begin());
    }
    if (best_axis < 0 || mid == begin || mid == end) {
        mid = begin + (end - begin) / 2;
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (extent[a] > extent[axis]) axis = a;
        std::nth_element(items.begin() + ptrdiff_t(begin), items.begin() + ptrdiff_t(mid), items.begin() + ptrdiff_t(end),
                         [axis](const Item& a, const Item& b) {
                             const float ca = a.bounds.centre[axis], cb = b.bounds.centre[axis];
                             return ca < cb || (ca == cb && a.light < b.light);
                         });
    }
    build_binary(out, items, begin, mid, depth + 1);
    const int right = build_binary(out, items, mid, end, depth + 1);
    out[size_t(index)].right = right;
    return index;
}

// The 4-wide node of the binary interior node b: its lanes are b's descendants, expanded
// breadth-first (the shallowest interior one first) until there are four or only leaves, so
// that every wide level takes at least two binary levels.
int LightSampler::collapse(const std::vector<BinaryNode>& binary, int b, int depth, uint64_t trail) {
    struct Lane {
        int node, level;
    };
    std::vector<Lane> lanes{{b + 1, 1}, {binary[size_t(b)].right, 1}};
    while (lanes.size() < 4) {
        int expand = -1;
        for (int k = 0; k < int(lanes.size()); ++k)
            if (binary[size_t(lanes[size_t(k)].node)].light < 0 && (expand < 0 || lanes[size_t(k)].level < lanes[size_t(expand)].level))
                expand = k;
        if (expand < 0) break;
        const Lane e = lanes[size_t(expand)];
        lanes[size_t(expand)] = {e.node + 1, e.level + 1};
        lanes.insert(lanes.begin() + expand + 1, Lane{binary[size_t(e.node)].right, e.level + 1});
    }
    const int index = int(nodes_.size());
    nodes_.emplace_back();
    set_sphere(nodes_[size_t(index)], binary[size_t(b)].bounds);
    for (int k = 0; k < int(lanes.size()); ++k) {
        const BinaryNode& lane = binary[size_t(lanes[size_t(k)].node)];
        const uint64_t lane_trail = trail | (uint64_t(k) << (2 * depth));
        nodes_[size_t(index)].bounds.set(k, lane.bounds);
        if (lane.light >= 0) {
            nodes_[size_t(index)].child[k] = ~lane.light;
            trails_[size_t(lane.light)] = {lane_trail, depth + 1};
        } else {
            const int child = collapse(binary, lanes[size_t(k)].node, depth + 1, lane_trail);
            nodes_[size_t(index)].child[k] = child;
        }
    }
    return index;
}

float LightSampler::infinite_share() const {
    if (infinite_.empty()) return 0.0f;
    if (nodes_.empty()) return 1.0f;
    return float(infinite_.size()) / float(infinite_.size() + 1);
}

namespace {

// A node's four importances at (p, n) and their sum: choose() and pmf() read both from here, so
// that they divide the same floats.
float lane_importances(const LightBounds4& bounds, const Vec3f& p, const Vec3f& n, float importance[4]) {
    bounds.importance(p, n).store(importance);
    return (importance[0] + importance[1]) + (importance[2] + importance[3]);
}

// The lane of a node whose share of [0, sum) holds u * sum (empty for a lane of importance 0;
// counting the bounds below it takes no branch and no division, which would wait for the sum),
// the last lane of positive importance where rounding leaves it past the sum; u is rescaled to
// [0, 1) within the lane.
int pick_lane(const float importance[4], float sum, float& u) {
    constexpr float kBelowOne = 0x1.fffffep-1f;
    const float c0 = importance[0], c1 = c0 + importance[1], c2 = c1 + importance[2];
    const float x = u * sum;
    int lane = int(x >= c0) + int(x >= c1) + int(x >= c2);
    while (!(importance[lane] / sum > 0)) --lane;  // (a lane of positive importance, not so small its share rounds to 0)
    const float below = lane == 0 ? 0.0f : lane == 1 ? c0 : lane == 2 ? c1 : c2;
    u = std::min(std::max(0.0f, x - below) / importance[lane], kBelowOne);
    return lane;
}

}  // namespace

LightChoice LightSampler::choose(const Vec3f& p, const Vec3f& n, float u) const {
    if (count_ == 0) return {};
    switch (kind_) {
        case LightSamplerKind::Power: return power_.choose(u);
        case LightSamplerKind::Uniform: return uniform_.choose(u);
        case LightSamplerKind::Bvh:
        case LightSamplerKind::Ris: break;
    }
    constexpr float kBelowOne = 0x1.fffffep-1f;
    const float share = infinite_share();
    if (u < share) {
        const size_t k = std::min(size_t(u / share * float(infinite_.size())), infinite_.size() - 1);
        return {infinite_[k], share / float(infinite_.size())};
    }
    u = std::min((u - share) / (1 - share), kBelowOne);
    float pmf = 1 - share;
    int node = 0;
    for (;;) {
        const Node& at = nodes_[size_t(node)];
        float importance[4];
        const float sum = lane_importances(at.bounds, p, n, importance);
        if (!(sum > 0)) return {};
        const int lane = pick_lane(importance, sum, u);
        pmf *= importance[lane] / sum;  // as pmf() multiplies it
        const int child = at.child[lane];
        if (child < 0) return {~child, pmf};
        node = child;
    }
}

int LightSampler::choose_split(const Vec3f& p, const Vec3f& n, float u, LightChoice* out, bool split) const {
    if (!split || !(split_ > 0) || nodes_.empty()) {
        out[0] = choose(p, n, u);
        return out[0].index >= 0 ? 1 : 0;
    }
    constexpr float kBelowOne = 0x1.fffffep-1f;
    const float share = infinite_share();
    if (u < share) {
        out[0] = choose(p, n, u);
        return 1;
    }
    u = std::min((u - share) / (1 - share), kBelowOne);
    // Depth first, a split node's lanes in order; every descent gets u (rescaled by its own choices).
    struct Open {
        int node, depth;
        float pmf, u;
    };
    Open stack[kMaxSplitLights];
    int open = 0, count = 0;
    stack[open++] = {0, 0, 1 - share, u};
    while (open > 0) {
        const Open o = stack[--open];
        const Node& at = nodes_[size_t(o.node)];
        float importance[4];
        const float sum = lane_importances(at.bounds, p, n, importance);
        if (!(sum > 0)) continue;
        if (splits(at, o.depth, p)) {
            for (int lane = 3; lane >= 0; --lane) {  // pushed last to first: taken first to last
                if (!(importance[lane] > 0)) continue;
                const int child = at.child[lane];
                if (child < 0) out[count++] = {~child, o.pmf};  // a leaf lane: its light at once
                else stack[open++] = {child, o.depth + 1, o.pmf, o.u};
            }
            continue;
        }
        float v = o.u;
        const int lane = pick_lane(importance, sum, v);
        const float pmf = o.pmf * (importance[lane] / sum);  // as pmf() multiplies it
        const int child = at.child[lane];
        if (child < 0) out[count++] = {~child, pmf};
        else stack[open++] = {child, o.depth + 1, pmf, v};
    }
    return count;
}

float LightSampler::pmf(const Vec3f& p, const Vec3f& n, int light, bool split) const {
    if (light < 0 || light >= count_) return 0.0f;
    switch (kind_) {
        case LightSamplerKind::Power: return power_.pmf(light);
        case LightSamplerKind::Uniform: return uniform_.pmf(light);
        case LightSamplerKind::Bvh:
        case LightSamplerKind::Ris: break;
    }
    const Trail& trail = trails_[size_t(light)];
    const float share = infinite_share();
    if (trail.depth < 0) return share / float(infinite_.size());
    float pmf = 1 - share;
    int node = 0;
    for (int level = 0; level < trail.depth; ++level) {
        const Node& at = nodes_[size_t(node)];
        float importance[4];
        const float sum = lane_importances(at.bounds, p, n, importance);
        const int lane = int((trail.lanes >> (2 * level)) & 3);
        if (!(sum > 0)) return 0.0f;
        if (split && splits(at, level, p)) {  // every lane of positive importance is descended into
            if (!(importance[lane] > 0)) return 0.0f;
        } else {
            pmf *= importance[lane] / sum;  // as choose() multiplies it
        }
        node = at.child[lane];
    }
    return pmf;
}

}  // namespace pathlab
