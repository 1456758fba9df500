#include "integrators/cache/surfel_tree.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>

namespace pathlab {
namespace {

constexpr uint32_t kLeafSize = 8;
constexpr float kNearField = 4;  // surfels closer than this many radii are traced
constexpr float kInPlane = 0.03f;  // x within atan(0.03) = 1.7 degrees of a disk's plane does not see it

// The real spherical harmonics of bands 0-2 at the unit direction w.
std::array<float, 9> sh_basis(const Vec3f& w) {
    return {0.282095f,
            0.488603f * w.y,
            0.488603f * w.z,
            0.488603f * w.x,
            1.092548f * w.x * w.y,
            1.092548f * w.y * w.z,
            0.315392f * (3 * w.z * w.z - 1),
            1.092548f * w.x * w.z,
            0.546274f * (w.x * w.x - w.y * w.y)};
}

// The clamped cosine's band weights A^_l (pi, 2 pi / 3, pi / 4) per coefficient, and (-1)^l.
constexpr float kBandWeight[9] = {kPi, 2 * kPi / 3, 2 * kPi / 3, 2 * kPi / 3, kPi / 4, kPi / 4, kPi / 4, kPi / 4, kPi / 4};
constexpr float kParity[9] = {1, -1, -1, -1, 1, 1, 1, 1, 1};

template <typename T> T evaluate(const std::array<T, 9>& c, const std::array<float, 9>& y) {
    T sum = c[0] * y[0];
    for (int k = 1; k < 9; ++k) sum += c[k] * y[k];
    return sum;
}

}  // namespace

struct SurfelTree::Element {
    float distance;
    uint32_t key;  // the surfel's index, or the surfel count + the node's
    bool disk;
    Vec3f a;       // square: the direction from x; disk: the centre
    Vec3f nd;      // disk: the normal
    float size;    // square: the solid angle; disk: the radius
    Rgb L;
    float extent;  // half its depth range (a surfel's radius, a cluster's half diagonal)

    // Nearest first, ties by key: the bits of a non-negative float order as the float does.
    uint64_t order() const { return (uint64_t(std::bit_cast<uint32_t>(distance)) << 32) | key; }
};

void SurfelTree::build(std::vector<Surfel> surfels, SurfelTreeFaults faults) {
    surfels_ = std::move(surfels);
    faults_ = faults;
    order_.resize(surfels_.size());
    for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
    nodes_.clear();
    if (surfels_.empty()) return;
    nodes_.emplace_back();
    build_node(0, 0, uint32_t(surfels_.size()), 0);
    update();
}

void SurfelTree::build_node(uint32_t index, uint32_t first, uint32_t count, int depth) {
    Vec3f lo(kInf), hi(-kInf), clo(kInf), chi(-kInf);
    Vec3d weighted(0.0);
    double area = 0;
    for (uint32_t k = first; k < first + count; ++k) {
        const Surfel& s = surfels_[order_[k]];
        lo = min(lo, s.p - Vec3f(s.radius)), hi = max(hi, s.p + Vec3f(s.radius));
        clo = min(clo, s.p), chi = max(chi, s.p);
        weighted += Vec3d(s.p) * double(s.area);
        area += s.area;
    }
    Node& node = nodes_[index];
    node.lo = lo, node.hi = hi;
    node.centre = area > 0 ? Vec3f(weighted / area) : (clo + chi) * 0.5f;
    node.first = first, node.count = count;
    node.child_first = node.child_count = 0;
    if (count <= kLeafSize || depth >= 32) return;

    // The surfels by octant about the middle of their centres' bounds (a stable counting sort).
    const Vec3f mid = (clo + chi) * 0.5f;
    const auto octant = [&](uint32_t i) {
        const Vec3f& p = surfels_[i].p;
        return int(p.x > mid.x) | (int(p.y > mid.y) << 1) | (int(p.z > mid.z) << 2);
    };
    uint32_t counts[8] = {};
    for (uint32_t k = first; k < first + count; ++k) ++counts[octant(order_[k])];
    int children = 0;
    for (const uint32_t c : counts) children += c > 0;
    if (children < 2) return;  // coincident centres: a larger leaf
    uint32_t start[8];
    for (int o = 0, s = first; o < 8; s += counts[o], ++o) start[o] = uint32_t(s);
    std::vector<uint32_t> sorted(count);
    uint32_t cursor[8];
    std::copy(start, start + 8, cursor);
    for (uint32_t k = first; k < first + count; ++k) {
        const uint32_t i = order_[k];
        sorted[cursor[octant(i)]++ - first] = i;
    }
    std::copy(sorted.begin(), sorted.end(), order_.begin() + first);

    const uint32_t child_first = uint32_t(nodes_.size());
    nodes_.resize(nodes_.size() + size_t(children));
    nodes_[index].child_first = child_first, nodes_[index].child_count = uint32_t(children);
    uint32_t c = child_first;
    for (int o = 0; o < 8; ++o)
        if (counts[o]) build_node(c++, start[o], counts[o], depth + 1);
}

void SurfelTree::update() {
    // Raw sums first (leaves from their surfels, parents from their children), then each node's
    // lobes and the residual coefficients.
    for (size_t k = nodes_.size(); k-- > 0;) {
        Node& node = nodes_[k];
        node.area_sh.fill(0.0f), node.power_sh.fill(Rgb(0.0f));
        node.area_normal = Vec3f(0.0f);
        for (int c = 0; c < 3; ++c) node.power_front[c] = node.power_back[c] = Vec3f(0.0f);
        if (node.child_count == 0) {
            for (uint32_t j = node.first; j < node.first + node.count; ++j) {
                const Surfel& s = surfels_[order_[j]];
                const std::array<float, 9> y = sh_basis(s.n);
                const float area = faults_.area_without_pi ? s.radius * s.radius : s.area;
                for (int c = 0; c < 9; ++c) {
                    const float front = kBandWeight[c] * y[c];
                    node.area_sh[c] += area * front;
                    node.power_sh[c] += (s.radiance[0] + s.radiance[1] * kParity[c]) * (s.area * front);
                }
                node.area_normal += s.n * area;
                for (int c = 0; c < 3; ++c) {
                    node.power_front[c] += s.n * (s.area * s.radiance[0][c]);
                    node.power_back[c] += s.n * (s.area * s.radiance[1][c]);
                }
            }
            if (faults_.power_without_cosine) {
                // Each side's A L in every direction: the constant A (L_front + L_back) / 2.
                node.power_sh.fill(Rgb(0.0f));
                for (int c = 0; c < 3; ++c) node.power_front[c] = node.power_back[c] = Vec3f(0.0f);
                Rgb sum(0.0f);
                for (uint32_t j = node.first; j < node.first + node.count; ++j) {
                    const Surfel& s = surfels_[order_[j]];
                    sum += (s.radiance[0] + s.radiance[1]) * (0.5f * s.area);
                }
                node.power_sh[0] = sum / 0.282095f;
            }
        } else {
            for (uint32_t c = node.child_first; c < node.child_first + node.child_count; ++c) {
                const Node& child = nodes_[c];
                for (int i = 0; i < 9; ++i) {
                    node.area_sh[i] += child.area_sh[i];
                    node.power_sh[i] += child.power_sh[i];
                }
                node.area_normal += child.area_normal;
                for (int i = 0; i < 3; ++i) node.power_front[i] += child.power_front[i], node.power_back[i] += child.power_back[i];
            }
        }
    }
    // The residuals: the sums less the lobes' own coefficients, |m| A^_l Y_lm(m / |m|) (the
    // back lobe's direction is -p_back).
    const auto lobe = [](const Vec3f& m) {
        std::array<float, 9> c{};
        const float len = length(m);
        if (!(len > 0)) return c;
        const std::array<float, 9> y = sh_basis(m / len);
        for (int i = 0; i < 9; ++i) c[i] = len * kBandWeight[i] * y[i];
        return c;
    };
    for (Node& node : nodes_) {
        node.area = node.area_sh, node.power = node.power_sh;
        const std::array<float, 9> a = lobe(node.area_normal);
        for (int i = 0; i < 9; ++i) node.area[i] -= a[i];
        for (int c = 0; c < 3; ++c) {
            const std::array<float, 9> f = lobe(node.power_front[c]), b = lobe(-node.power_back[c]);
            for (int i = 0; i < 9; ++i) node.power[i][c] -= f[i] + b[i];
        }
    }
}

void SurfelTree::add_surfel(uint32_t i, const Vec3f& x, const Vec3f& n, std::vector<Element>& out) const {
    const Surfel& s = surfels_[i];
    const Vec3f v = s.p - x;
    const float h = -dot(v, s.n);  // x's height above the disk's plane
    const float dist = length(v);
    // Left out: a disk seen edge-on (x within 1.7 degrees of its plane: a neighbour on a flat
    // surface), and on the outside of a curved surface a neighbour's tangent disk, which lies a
    // little above the surface and would cover x from behind like a lid (x less than a radius
    // behind it, the normals within 25 degrees).
    if (std::abs(h) <= kInPlane * dist || (h < 0 && -h < s.radius && dot(n, s.n) > 0.9f)) return;
    const Rgb& L = s.radiance[h > 0 ? 0 : 1];
    if (dist < kNearField * s.radius) {
        out.push_back({dist, i, true, s.p, s.n, s.radius, L, s.radius * std::sqrt(std::max(0.0f, 1 - h * h / (dist * dist)))});
        return;
    }
    const Vec3f d = v / dist;
    if (!(dot(d, n) > 0)) return;
    // Its depth range along d: r sin(angle between n and d).
    const float extent = s.radius * std::sqrt(std::max(0.0f, 1 - h * h / (dist * dist)));
    const float omega = faults_.surfel_without_cosine ? s.area / (dist * dist) : s.area * std::abs(h) / (dist * dist * dist);
    out.push_back({dist, i, false, d, Vec3f(0.0f), omega, L, extent});
}

Rgb SurfelTree::draw(std::vector<Element>& elements, const Vec3f& x, const Vec3f& n, int resolution) const {
    thread_local std::unique_ptr<MicroBuffer> buffer;
    if (!buffer || buffer->resolution() != resolution) buffer = std::make_unique<MicroBuffer>(resolution);
    // Sorted by (distance, key), which is unique: a total order, whatever order they came in.
    thread_local std::vector<std::pair<uint64_t, uint32_t>> sorted;
    sorted.resize(elements.size());
    for (uint32_t i = 0; i < elements.size(); ++i) sorted[i] = {elements[i].order(), i};
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    buffer->clear(x, Frame(n));
    for (const auto& [order, index] : sorted) {
        const Element& e = elements[index];
        if (e.disk) buffer->add_disk(e.a, e.nd, e.size, e.L, e.distance - e.extent, e.distance + e.extent);
        else buffer->add_square(e.a, e.size, e.L, e.distance - e.extent, e.distance + e.extent);
    }
    return buffer->irradiance();
}

Rgb SurfelTree::gather(const Vec3f& x, const Vec3f& n, const GatherSettings& settings, GatherCounters* counters) const {
    thread_local std::vector<Element> elements;
    thread_local std::vector<uint32_t> stack;
    elements.clear(), stack.clear();
    if (!nodes_.empty()) stack.push_back(0);
    const uint32_t surfel_count = uint32_t(surfels_.size());
    uint64_t visited = 0, clusters = 0;
    while (!stack.empty()) {
        const uint32_t index = stack.back();
        stack.pop_back();
        const Node& node = nodes_[index];
        ++visited;
        // Wholly below the tangent plane: nothing of it is in view.
        const Vec3f corner(n.x > 0 ? node.hi.x : node.lo.x, n.y > 0 ? node.hi.y : node.lo.y, n.z > 0 ? node.hi.z : node.lo.z);
        if (!(dot(corner - x, n) > 0)) continue;
        const bool inside = x.x >= node.lo.x && x.x <= node.hi.x && x.y >= node.lo.y && x.y <= node.hi.y && x.z >= node.lo.z &&
                            x.z <= node.hi.z;
        if (settings.cutoff > 0 && !inside) {
            const Vec3f v = node.centre - x;
            const float r2 = dot(v, v), r = std::sqrt(r2);
            const Vec3f w = v * (-1 / r);  // from the cluster towards x
            const std::array<float, 9> y = sh_basis(w);
            // A_front(w) = max(0, m.w) + R(w), A_back(w) = A_front(-w) = max(0, -m.w) + R(-w), and
            // R(+-w) = even bands +- odd bands.
            const float odd = node.area[1] * y[1] + node.area[2] * y[2] + node.area[3] * y[3];
            const float even = node.area[0] * y[0] + node.area[4] * y[4] + node.area[5] * y[5] + node.area[6] * y[6] + node.area[7] * y[7] +
                               node.area[8] * y[8];
            const float mw = dot(node.area_normal, w);
            const float area = std::max({std::max(mw, 0.0f) + even + odd, std::max(-mw, 0.0f) + even - odd, 0.0f});
            const float omega = area / r2;
            if (!(omega > settings.cutoff)) {
                const Vec3f d = v / r;
                if (area > 0 && dot(d, n) > 0) {
                    Rgb P = evaluate(node.power, y);
                    for (int c = 0; c < 3; ++c)
                        P[c] += std::max(dot(node.power_front[c], w), 0.0f) + std::max(-dot(node.power_back[c], w), 0.0f);
                    const Rgb L = max(P, Rgb(0.0f)) / area;
                    // Its depth range along d: the bounds' half size projected onto d.
                    const Vec3f half = (node.hi - node.lo) * 0.5f;
                    const float extent = std::abs(d.x) * half.x + std::abs(d.y) * half.y + std::abs(d.z) * half.z;
                    elements.push_back({r, surfel_count + index, false, d, Vec3f(0.0f), omega, L, extent});
                    ++clusters;
                }
                continue;
            }
        }
        if (node.child_count == 0) {
            for (uint32_t k = node.first; k < node.first + node.count; ++k) add_surfel(order_[k], x, n, elements);
            continue;
        }
        for (uint32_t c = node.child_first + node.child_count; c-- > node.child_first;) stack.push_back(c);
    }
    if (counters) {
        ++counters->gathers;
        counters->nodes += visited;
        counters->clusters += clusters;
        counters->surfels += elements.size() - clusters;
    }
    return draw(elements, x, n, settings.resolution);
}

Rgb SurfelTree::gather_brute_force(const Vec3f& x, const Vec3f& n, const GatherSettings& settings) const {
    thread_local std::vector<Element> elements;
    elements.clear();
    for (uint32_t i = 0; i < surfels_.size(); ++i) add_surfel(i, x, n, elements);
    return draw(elements, x, n, settings.resolution);
}

}  // namespace pathlab
