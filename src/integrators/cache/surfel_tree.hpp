// The hierarchy of point-based global illumination (Christensen 2008): an octree over the
// surfels whose nodes (clusters) carry an aggregate of their surfels, and the gather that
// traverses it with a solid-angle cutoff into a micro-buffer.
//
// Octree: a node splits its surfels' centres by the octants about the middle of their bounds;
// leaves hold at most 8 surfels. Children lie after their parent, contiguously; each node
// lists its surfels as one range of order_ (the surfels in leaf order).
//
// Aggregate (per node, up to spherical-harmonic band 2, 9 real coefficients each):
//   A_front(w) = sum_i A_i max(0,  n_i . w),   A_back(w) = sum_i A_i max(0, -n_i . w)
//   I(w)       = sum_i A_i (L_i,front max(0, n_i . w) + L_i,back max(0, -n_i . w))   per colour
// w a direction leaving the cluster. Each surfel's clamped cosine projects exactly onto the
// bands as max(0, s . w) = sum_lm  A^_l Y_lm(s) Y_lm(w) + (bands > 2), A^ = (pi, 2 pi/3, pi/4)
// (Ramamoorthi and Hanrahan's convolution weights), and a cluster's coefficients are the sum of
// its surfels'. Seen from x at distance r from the cluster's centre c (area-weighted mean of its
// surfels' centres), w = (x - c)/r, the cluster's projected area is A(w) = max(A_front, A_back)
// (both equal the silhouette for a closed surface, and one of them is exact for a flat sheet:
// taking the sum would count a closed surface twice), its solid angle omega = A(w)/r^2 and its
// radiance I(w)/A(w).
//
// Gather at x with normal n: from the root, a node wholly below x's tangent plane is skipped; a
// node is opened (its children visited) when the cutoff is 0, when x lies in its bounds, or when
// omega > cutoff; otherwise it is drawn as one square of solid angle omega. A leaf's surfels are
// drawn one by one: a surfel closer than 4 radii is traced into the micro-buffer (near field),
// others are squares of solid angle A |n_i . d| / r^2 (mid field); the side facing x gives the
// radiance. The elements are then sorted by distance (ties by index) and drawn nearest first,
// so the result does not depend on the traversal's order: with the cutoff at 0 it is the
// brute-force gather (every surfel drawn individually) bit for bit.
#pragma once

#include <array>
#include <vector>

#include "integrators/cache/micro_buffer.hpp"
#include "integrators/cache/surfels.hpp"

namespace pathlab {

// Deliberate mistakes for the tests (to see them fail).
struct SurfelTreeFaults {
    bool power_without_cosine = false;  // a cluster's I(w): the surfels' A L in every direction (no cosine)
    bool area_without_pi = false;       // a cluster's projected area from r^2 instead of pi r^2
    bool surfel_without_cosine = false; // a surfel's solid angle A / r^2 (its projection's cosine missing)
};

struct GatherSettings {
    float cutoff = 0.05f;  // solid angle (sr) above which a cluster is opened; 0: brute force
    int resolution = 16;   // micro-buffer side (pixels)
};

struct GatherCounters {
    uint64_t gathers = 0, nodes = 0, clusters = 0, surfels = 0;
};

class SurfelTree {
public:
    SurfelTree() = default;
    SurfelTree(std::vector<Surfel> surfels, SurfelTreeFaults faults = {}) { build(std::move(surfels), faults); }
    void build(std::vector<Surfel> surfels, SurfelTreeFaults faults = {});
    // The aggregates again from the surfels' radiance (after a bounce changed them).
    void update();

    // The irradiance at x (normal n, unit) from the surfels: the hierarchical gather, and the
    // brute-force one drawing every surfel.
    Rgb gather(const Vec3f& x, const Vec3f& n, const GatherSettings& settings, GatherCounters* counters = nullptr) const;
    Rgb gather_brute_force(const Vec3f& x, const Vec3f& n, const GatherSettings& settings) const;

    const std::vector<Surfel>& surfels() const { return surfels_; }
    std::vector<Surfel>& surfels() { return surfels_; }
    size_t node_count() const { return nodes_.size(); }

private:
    struct Node {
        Vec3f lo{0.0f}, hi{0.0f};  // bounds of its surfels' disks
        Vec3f centre{0.0f};        // area-weighted mean of its surfels' centres
        uint32_t first = 0, count = 0;              // surfels: order_[first, first + count)
        uint32_t child_first = 0, child_count = 0;  // children: nodes_[child_first, ...); 0: a leaf
        // The aggregate: A_front(w) = max(0, m . w) + the residual's coefficients `area`, and
        // I(w) = max(0, p_front . w) + max(0, -p_back . w) + the residual `power` (per colour).
        Vec3f area_normal{0.0f};                   // m = sum A_i n_i
        Vec3f power_front[3], power_back[3];       // p = sum A_i L_i n_i per colour, of each side
        std::array<float, 9> area{};               // residual coefficients
        std::array<Rgb, 9> power{};
        std::array<float, 9> area_sh{};            // the plain sums of the surfels' coefficients
        std::array<Rgb, 9> power_sh{};
    };
    struct Element;

    void build_node(uint32_t index, uint32_t first, uint32_t count, int depth);
    void add_surfel(uint32_t i, const Vec3f& x, const Vec3f& n, std::vector<Element>& out) const;
    Rgb draw(std::vector<Element>& elements, const Vec3f& x, const Vec3f& n, int resolution) const;

    std::vector<Surfel> surfels_;
    std::vector<uint32_t> order_;
    std::vector<Node> nodes_;
    SurfelTreeFaults faults_;
};

}  // namespace pathlab
