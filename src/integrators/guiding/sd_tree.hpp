// The SD-tree of practical path guiding (Müller, Gross and Novák, "Practical Path Guiding for
// Efficient Light-Transport Simulation", EGSR 2017): an estimate of the radiance arriving at
// every point of the scene from every direction, learned from the paths of training passes and
// sampled to choose where paths go next.
//
//   spatial part      a binary tree over the scene's bounding cube, splitting x, y, z in turn;
//                     a leaf is split when the last iteration recorded more than
//                     c * sqrt(spp of that iteration) path vertices in it (c = 12000);
//   directional part  in every spatial leaf, a quadtree over the square of cylindrical
//                     coordinates (cos theta, phi / 2 pi), an area-preserving map of the sphere:
//                     a density p(u) on the square is the solid-angle density p(u) / (4 pi).
//                     A node is split where it holds more than rho = 1% of the leaf's energy
//                     (down to depth 20) and merged where it holds less.
//
// Each leaf holds two quadtrees: the sampling one (what the previous iteration learned) and the
// building one, which the current iteration's records fill. After an iteration refine() splits
// the spatial leaves, makes every building tree the sampling tree and gives the next building
// tree the structure its energy asks for.
//
// A record is (vertex position, direction of the arriving light, value = the radiance estimate
// arriving from that direction over the density with which the direction was sampled), so that
// a quadtree cell's sum estimates the integral of the arriving radiance over the cell.
// With --guiding vmm the directional part is a mixture of von Mises-Fisher lobes instead
// (vmf_mixture.hpp; Vorba et al. 2014's model in the spatial tree of this one, as Open PGL keeps
// its mixtures in a kd-tree): the same records feed its on-line EM, which goes on across the
// iterations (a leaf's fit is not restarted), and refine() hands its mixture to the sampling side.
//
// record() is not thread-safe: records are added in a fixed order (the training loop's pixel
// order), which keeps the tree, and every guided image, the same with any thread count.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "integrators/guiding/guiding_model.hpp"
#include "integrators/guiding/vmf_mixture.hpp"

namespace pathlab {

// The cylindrical map between unit directions and the unit square (equal-area).
Vec2f direction_to_square(const Vec3f& d);
Vec3f square_to_direction(const Vec2f& u);

class QuadTree {
public:
    QuadTree();  // one node: four empty quadrants

    // Adds `value` to every node on the way down to the leaf quadrant holding u.
    void record(const Vec2f& u, float value);
    // The density on the unit square of sample() (0 where the tree holds no energy).
    float pdf(const Vec2f& u) const;
    // A point of the unit square with density pdf() (random numbers r in [0, 1)^2).
    Vec2f sample(Vec2f r) const;
    // An empty tree whose structure follows this tree's energy: quadrants holding more than
    // `rho` of the total are split (down to max_depth), the rest are leaves.
    QuadTree refined(float rho, int max_depth) const;

    double energy() const;  // the sum of everything recorded
    size_t node_count() const { return nodes_.size(); }
    size_t memory_bytes() const { return nodes_.capacity() * sizeof(Node); }
    int depth() const;

private:
    struct Node {
        std::array<float, 4> sum{};       // per quadrant: x >= 1/2 is +1, y >= 1/2 is +2
        std::array<uint32_t, 4> child{};  // 0: the quadrant is a leaf (node 0, the root, is no one's child)
    };
    std::vector<Node> nodes_;
};

// The probability of sampling the BSDF rather than the tree, learned per leaf (--guiding-fraction
// learned; Müller, "Practical Path Guiding in Production", 2019): a = sigmoid(theta), theta moved
// by Adam along the gradient of the KL divergence from the product F = f Li |cos| (normalised) to
// the continuation's mixture q = a p_bsdf + (1 - a) p_tree, estimated at each guided training
// vertex from its direction w (drawn from q):
//   dD/dtheta = -(F(w) / q(w)) (p_bsdf(w) - p_tree(w)) / q(w) a (1 - a)
// (an L2 term 0.01 theta pulls theta towards 0, a = 1/2, where the vertices say little; theta is
// kept within [-4, 4], a within [0.018, 0.982], so that neither half is ever off).
struct BsdfFractionFit {
    static constexpr float kLearningRate = 0.01f, kRegularisation = 0.01f, kMaxTheta = 4.0f;
    float theta = 0, m = 0, v = 0;  // the parameter and Adam's moments
    float beta1_t = 1, beta2_t = 1;  // Adam's decay rates to the power of the steps taken
    float a = 0.5f;                  // sigmoid(theta), kept for the paths that read it

    float fraction() const { return a; }
    void step(float gradient);
    // The gradient's estimate from one direction drawn from the mixture with fraction `fraction`:
    // F / q there, the mixture's density q and its two halves' densities.
    static float gradient(float F_over_q, float q, float p_bsdf, float p_tree, float fraction) {
        return -F_over_q * (p_bsdf - p_tree) / q * fraction * (1 - fraction);
    }
};

struct GuidingLeaf {
    GuidingModel model = GuidingModel::kSdTree;
    QuadTree sampling, building;  // kSdTree
    VmfMixture mixture;           // kVmm: the sampling mixture, and the fit that goes on learning
    VmfMixtureFit fit;
    uint64_t records = 0;  // vertices recorded in this iteration
    // Whether the sampling tree holds any energy (else guiding is off here: BSDF sampling only).
    bool usable = false;
    // The mean radiance the path vertices in the leaf sent back along their paths (the previous
    // iteration's; 0: none known), for adjoint-driven Russian roulette; and this iteration's sums.
    float outgoing = 0;
    double outgoing_sum = 0;
    uint64_t outgoing_count = 0;
    BsdfFractionFit fraction;  // --guiding-fraction learned (a split leaf's children start from its fit)

    // The sampling distribution's density per steradian of the world direction d (0 where the
    // leaf does not guide), and a direction drawn from it (r in [0, 1)^2).
    float pdf(const Vec3f& d) const;
    Vec3f sample(Vec2f r) const;
};

class SdTree {
public:
    static constexpr float kSplitConstant = 12000.0f;  // c
    static constexpr float kEnergyFraction = 0.01f;    // rho
    static constexpr int kMaxQuadDepth = 20;

    SdTree() = default;
    // A tree over the cube of half-side `radius` around `center` (the scene's bounds), whose
    // leaves learn directions by `model`.
    SdTree(const Vec3f& center, float radius, GuidingModel model = GuidingModel::kSdTree);

    // The leaf whose cell holds p (points outside the cube go to the nearest cell).
    const GuidingLeaf& leaf(const Vec3f& p) const { return leaves_[leaf_index(p)]; }
    GuidingLeaf& leaf(const Vec3f& p) { return leaves_[leaf_index(p)]; }
    void record(const Vec3f& p, const Vec3f& direction, float value);
    // The radiance a path vertex at p sent back towards where the path came from (an estimate).
    void record_outgoing(const Vec3f& p, float radiance);
    // One step of the BSDF fraction's fit of the leaf holding p (BsdfFractionFit).
    void record_fraction_gradient(const Vec3f& p, float gradient);

    // After an iteration of `iteration_spp` samples per pixel: split, swap, restructure.
    void refine(uint64_t iteration_spp);

    size_t leaf_count() const { return leaves_.size(); }
    size_t spatial_depth() const;
    const std::vector<GuidingLeaf>& leaves() const { return leaves_; }
    // The bytes the trees use.
    size_t memory_bytes() const;

private:
    struct Node {
        uint32_t child[2] = {0, 0};  // 0: a leaf
        uint32_t leaf = 0;           // index into leaves_, for a leaf
        uint8_t axis = 0;
    };
    size_t leaf_index(const Vec3f& p) const;
    void split(uint32_t node);

    Vec3f min_{0.0f};
    float size_ = 1.0f;
    std::vector<Node> nodes_{Node{}};
    std::vector<GuidingLeaf> leaves_{GuidingLeaf{}};
};

}  // namespace pathlab
