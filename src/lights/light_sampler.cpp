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
                           const std::vector<int>& emitter_of)
    : kind_(kind), count_(int(lights.size())), candidates_(kind == LightSamplerKind::Ris ? candidates : 1) {
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
    if (!items.empty()) {
        nodes_.reserve(2 * items.size() - 1);
        build(items, 0, items.size(), 0, 0);
    }
}

int LightSampler::build(std::vector<Item>& items, size_t begin, size_t end, int depth, uint64_t bits) {
    const int index = int(nodes_.size());
    nodes_.push_back({});
    LightBounds all;
    Vec3f clo(kInf), chi(-kInf);
    for (size_t i = begin; i < end; ++i) {
        all = unite(all, items[i].bounds);
        const Vec3f c = items[i].bounds.centre;
        clo = min(clo, c), chi = max(chi, c);
    }
    nodes_[size_t(index)].bounds = all.compact();
    if (end - begin == 1) {
        nodes_[size_t(index)].light = items[begin].light;
        trails_[size_t(items[begin].light)] = {bits, depth};
        return index;
    }
    // The split: binned surface area orientation heuristic over the centroids (12 buckets per
    // axis, each axis's cost scaled by how thin the node is along it); by count at the
    // median when the centroids coincide or the tree grows too deep for a 64-bit trail.
    constexpr int kBuckets = 12;
    size_t mid = begin + (end - begin) / 2;
    const Vec3f extent = chi - clo;
    const auto bucket_of = [&](const Item& item, int axis) {
        return std::clamp(int(float(kBuckets) * (item.bounds.centre[axis] - clo[axis]) / extent[axis]), 0, kBuckets - 1);
    };
    const float longest = max_component(extent);
    int best_axis = -1;
    float best_plane = 0, best_cost = kInf;
    if (depth < 56)
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
    build(items, begin, mid, depth + 1, bits);
    nodes_[size_t(index)].right = build(items, mid, end, depth + 1, bits | (uint64_t(1) << depth));
    return index;
}

float LightSampler::infinite_share() const {
    if (infinite_.empty()) return 0.0f;
    if (nodes_.empty()) return 1.0f;
    return float(infinite_.size()) / float(infinite_.size() + 1);
}

float LightSampler::branch_probability(float left, float right, bool take_right) {
    return (take_right ? right : left) / (left + right);
}

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
    if (!(nodes_[0].bounds.importance(p, n) > 0)) return {};
    float pmf = 1 - share;
    size_t node = 0;
    while (nodes_[node].light < 0) {
        const size_t left = node + 1, right = size_t(nodes_[node].right);
        const float il = nodes_[left].bounds.importance(p, n), ir = nodes_[right].bounds.importance(p, n);
        if (!(il + ir > 0)) return {};
        const float p_left = branch_probability(il, ir, false);
        if (u < p_left) {
            node = left, pmf *= p_left, u = std::min(u / p_left, kBelowOne);
        } else {
            node = right, pmf *= branch_probability(il, ir, true), u = std::min((u - p_left) / (1 - p_left), kBelowOne);
        }
    }
    return {nodes_[node].light, pmf};
}

float LightSampler::pmf(const Vec3f& p, const Vec3f& n, int light) const {
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
    if (!(nodes_[0].bounds.importance(p, n) > 0)) return 0.0f;
    float pmf = 1 - share;
    size_t node = 0;
    for (int level = 0; level < trail.depth; ++level) {
        const size_t left = node + 1, right = size_t(nodes_[node].right);
        const float il = nodes_[left].bounds.importance(p, n), ir = nodes_[right].bounds.importance(p, n);
        if (!(il + ir > 0)) return 0.0f;
        const bool take_right = (trail.bits >> level) & 1;
        pmf *= branch_probability(il, ir, take_right);
        node = take_right ? right : left;
    }
    return pmf;
}

}  // namespace pathlab
