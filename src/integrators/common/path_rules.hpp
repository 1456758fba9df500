// When a path may go on: the depth limit and Russian roulette, shared by the path tracers.
//
// Depth counts bounces: a path camera -> x1 -> light has one bounce (direct illumination), so
// max_depth = 1 gives direct lighting only. With --null-depth skip a straight pass through a
// surface (a kLobeNull sample) is no bounce (is_bounce). Russian roulette starts after rr_depth bounces
// (never if rr_depth < 0): the path survives with probability q = clamp(max(beta), 0.05, 1)
// and its throughput beta is divided by q, which keeps the estimator unbiased; the lower
// bound keeps 1/q bounded. A hard cap of kMaxBounces guards against paths that never end
// (albedos above 1, as the course's glossy spheres have); it truncates a vanishing tail.
#pragma once

#include <algorithm>

#include "bsdfs/bsdf_sample.hpp"
#include "samplers/sampler.hpp"
#include "integrators/integrator.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

inline constexpr int kMaxBounces = 1024;
// The bounces a path may make under a --max-depth (negative: unlimited, up to the cap).
inline constexpr int bounce_limit(int max_depth) { return max_depth < 0 ? kMaxBounces : std::min(max_depth, kMaxBounces); }

// The scene-file parameters of every path tracer. Mitsuba counts path segments, pathlab
// bounces: max_depth 2 is direct illumination, one bounce (the reader converts).
inline std::vector<ParamInfo> path_params() {
    return {{"max_depth", ParamType::Integer, "-1",
             "longest path in Mitsuba's convention: -1 unlimited, 2 direct light only (pathlab's bounces: max_depth - 1)", "maxDepth"},
            {"rr_depth", ParamType::Integer, "4",
             "path depth at which Russian roulette starts, Mitsuba's convention (pathlab's bounces: rr_depth - 1; --rr-depth wins)", "rrDepth"},
            {"hide_emitters", ParamType::Boolean, "false", "emitters (and the environment) seen directly are black", "hideEmitters"},
            {"samples_per_pass", ParamType::Integer, "-1",
             "accepted and ignored (noted): pathlab adds one sample per pixel per pass and stops on --spp or --time", "samplesPerPass"},
            {"strict_normals", ParamType::Boolean, "false", "accepted and ignored (noted): pathlab's shading-normal handling is its own", "strictNormals"}};
}

// The options with max_depth cut to only_length when only paths of that length count.
inline IntegratorOptions limited_to_length(IntegratorOptions o) {
    if (o.only_length >= 0 && (o.max_depth < 0 || o.max_depth > o.only_length)) o.max_depth = std::max(1, o.only_length);
    return o;
}

// Whether paths of this many bounces count in the image: all, or one length only (--only-length),
// without the emitters seen directly when they are hidden.
inline bool length_counts(const IntegratorOptions& o, int length) {
    return (o.only_length < 0 || o.only_length == length) && !(o.hide_emitters && length == 0);
}

class PathRules {
public:
    explicit PathRules(const IntegratorOptions& o)
        : max_depth_(bounce_limit(o.max_depth)), rr_depth_(o.rr_depth), power_mis_(o.mis_power),
          skip_null_(o.skip_null_events), hide_emitters_(o.hide_emitters) {}

    // The path tracers' MIS heuristic: the power heuristic (--mis power), else the balance one.
    bool power_mis() const { return power_mis_; }

    // May a path that has made `bounces` bounces make one more?
    bool may_bounce(int bounces) const { return bounces < max_depth_; }

    // --null-depth skip: a path at its depth limit may still pass straight through surfaces.
    bool skips_null() const { return skip_null_; }
    // Whether a sampled direction makes a bounce (not a straight pass under --null-depth skip).
    bool is_bounce(uint32_t sampled_lobe) const { return !(skip_null_ && (sampled_lobe & kLobeNull)); }
    // Paths of no bounce (emitters seen directly, also through a null surface) are hidden.
    bool hides_emitters() const { return hide_emitters_; }

    // Called after bounce number `bounces` (1-based) updated beta (RGB or spectral: q from its
    // largest channel or lane); false ends the path.
    template <class Colour>
    bool survive_roulette(int bounces, Colour& beta, Sampler& sampler) const {
        if (rr_depth_ < 0 || bounces < rr_depth_) return true;
        const float q = std::clamp(max_component(beta), 0.05f, 1.0f);
        if (sampler.next1d() >= q) return false;
        beta /= q;
        return true;
    }

    // The same on beta / density, the weight of a path whose density is not 1 (volpath's spectral
    // MIS over the channels: media/medium.hpp); pt-mis's roulette exactly when the density is 1.
    template <class Colour>
    bool survive_roulette(int bounces, Colour& beta, float density, Sampler& sampler) const {
        if (density == 1) return survive_roulette(bounces, beta, sampler);
        Colour weight = beta / density;
        if (!survive_roulette(bounces, weight, sampler)) return false;
        beta = weight * density;
        return true;
    }

    // Whether survive_roulette(bounces, ...) plays roulette at all (and draws a random number),
    // for code that replays its decisions (diff/path_replay.cpp).
    bool roulette_applies(int bounces) const { return !(rr_depth_ < 0 || bounces < rr_depth_); }

private:
    int max_depth_;
    int rr_depth_;
    bool power_mis_;
    bool skip_null_;
    bool hide_emitters_;
};

}  // namespace pathlab
