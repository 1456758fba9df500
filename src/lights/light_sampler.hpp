// Choosing the light that next-event estimation samples at a point (--light-sampler):
//   uniform  every emitter with the same probability, an emitting mesh's triangles by their areas
//            (Mitsuba 3's choice: a mesh lamp is one emitter, however many triangles it has)
//   power    in proportion to its power (light_distribution.hpp; light paths always start so)
//   bvh      down a bounding volume hierarchy over the lights at finite positions, each step
//            choosing a child in proportion to its importance at the point (light_bounds.hpp),
//            as pbrt-v4 and Cycles do; the lights at infinity (environment, directional) beside
//            the tree with a fixed share n_inf / (n_inf + 1), uniformly among them
//   ris      bvh's choices as the candidates of resampled importance sampling: next-event
//            estimation draws candidates() light samples and keeps one by its unshadowed
//            contribution (integrators/common/light_resampling.hpp); choose and pmf are bvh's
// pmf(p, n, i) is the probability with which choose(p, n, u) returns light i: the BSDF-sampled
// half of MIS weighs an emitter it hits with it (for bvh, the same arithmetic along the light's
// path in the tree).
//
// Adaptive splitting (bvh with --light-split t; Conty Estevez and Kulla 2018, section 5): where a
// node of the top kMaxSplitDepth levels is close to the point (its bounding sphere's radius over
// the distance to its centre above t), its bound says little about which of its lights matter
// (for lights spread uniformly in distance over [d - r, d + r], the squared coefficient of
// variation of 1/d^2 is 4/3 (r/d)^2 / (1 - (r/d)^2), a function of r/d alone), so instead of
// choosing one of its children every child of positive importance is descended into, each giving
// its own light sample. choose_split returns them all (at most kMaxSplitLights); a light's pmf is
// then the probability that the one descent through its part of the tree ends at it (the product
// of the choices below the split nodes on its path): the expected number of samples it gets, the
// density the balance heuristic needs, and what pmf(p, n, i) returns.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lights/light_bounds.hpp"
#include "lights/light_distribution.hpp"

namespace pathlab {

enum class LightSamplerKind { Uniform, Power, Bvh, Ris };

const char* light_sampler_name(LightSamplerKind kind);
std::optional<LightSamplerKind> parse_light_sampler(const std::string& name);
inline constexpr const char* kLightSamplerNames = "uniform, power, bvh, ris";
inline constexpr int kDefaultRisCandidates = 4;  // --ris-candidates
inline constexpr int kMaxRisCandidates = 64;
inline constexpr float kDefaultLightSplit = 0;  // --light-split (bvh)
inline constexpr float kMaxLightSplit = 100;
// Levels of the 4-wide tree where a node may split: the root only (4 samples at most); splitting
// its children too (16) cost more than it gained (docs/lights.md).
inline constexpr int kMaxSplitDepth = 1;
inline constexpr int kMaxSplitLights = 1 << (2 * kMaxSplitDepth);

class LightSampler {
public:
    LightSampler() = default;
    // emitter_of[i]: the emitter light i belongs to (an emitting mesh is one emitter of many
    // triangle lights); empty: every light is its own.
    LightSampler(const std::vector<Light>& lights, const SceneSphere& sphere, LightSamplerKind kind,
                 int candidates = kDefaultRisCandidates, const std::vector<int>& emitter_of = {}, float split = 0);

    LightSamplerKind kind() const { return kind_; }
    // The light samples next-event estimation draws to keep one (ris); 1 for the other kinds.
    int candidates() const { return candidates_; }
    // The splitting threshold (bvh; 0: no splitting).
    float split() const { return split_; }
    // A light for the point p with normal n (n = 0 in a medium), and its probability (without
    // splitting: ris's candidates and light paths draw one light).
    LightChoice choose(const Vec3f& p, const Vec3f& n, float u) const;
    // Next-event estimation's lights: with splitting (and `split`: a vertex that splits), up to
    // kMaxSplitLights into out (each with its pmf), else choose's one; returns how many.
    int choose_split(const Vec3f& p, const Vec3f& n, float u, LightChoice* out, bool split = true) const;
    // `split`: of the choice choose_split makes (false: of choose's, at a vertex that does not split).
    float pmf(const Vec3f& p, const Vec3f& n, int light, bool split = true) const;

    // The tree's size (bvh): nodes and bytes.
    size_t nodes() const { return nodes_.size(); }
    size_t bytes() const { return nodes_.size() * sizeof(Node) + trails_.size() * sizeof(Trail) + infinite_.size() * sizeof(int); }

private:
    // A node of the 4-wide tree: its children's bounds side by side, so that one pass of 4-wide
    // arithmetic gives the importance of each (13 levels of 2 scalar bounds become 7 of 4 lanes
    // for 4608 lights). The tree is built binary, then every node takes its grandchildren.
    struct alignas(64) Node {
        LightBounds4 bounds;
        // >= 0: a node; < 0: a leaf, ~light; an empty lane has phi 0, so importance 0, and is never taken.
        int32_t child[4] = {INT32_MIN, INT32_MIN, INT32_MIN, INT32_MIN};
        float centre[3] = {0, 0, 0}, radius = 0;  // the node's own bounding sphere (splitting)
    };
    struct Trail {  // a light's leaf: the lanes (2 bits per level, the root's lowest) that lead to it
        uint64_t lanes = 0;
        int32_t depth = -1;  // levels; -1: not in the tree
    };
    struct Item {
        LightBounds bounds;
        int light;
    };
    struct BinaryNode {
        LightBounds bounds;
        int right = -1;  // interior: the second child (the first follows the node)
        int light = -1;  // leaf: the light
    };
    static int build_binary(std::vector<BinaryNode>& out, std::vector<Item>& items, size_t begin, size_t end, int depth);
    int collapse(const std::vector<BinaryNode>& binary, int b, int depth, uint64_t trail);
    float infinite_share() const;
    bool splits(const Node& node, int depth, const Vec3f& p) const {
        if (depth >= kMaxSplitDepth || !(split_ > 0)) return false;
        const float dx = p.x - node.centre[0], dy = p.y - node.centre[1], dz = p.z - node.centre[2];
        return node.radius * node.radius > split_ * split_ * (dx * dx + dy * dy + dz * dz);
    }

    LightSamplerKind kind_ = LightSamplerKind::Power;
    int count_ = 0;
    int candidates_ = 1;
    float split_ = 0;  // --light-split (bvh)
    LightDistribution power_;    // power: by power
    LightDistribution uniform_;  // uniform: every emitter alike, an emitting mesh's triangles by area (Mitsuba 3's choice)
    std::vector<Node> nodes_;
    std::vector<Trail> trails_;  // by light
    std::vector<int> infinite_;  // the lights at infinity
};

}  // namespace pathlab
