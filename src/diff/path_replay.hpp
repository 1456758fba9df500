// Gradients of a rendered image with respect to scene parameters (parameters.hpp) by path
// replay backpropagation (Vicini, Speierer and Jakob 2021, "Path Replay Backpropagation"), for
// the estimator of pt-mis (next-event estimation and BSDF sampling combined by MIS at every
// vertex, Russian roulette), with detached sampling as Mitsuba 3's `prb`; in a scene with
// participating media, volpath's (its free flights, phase samples and shadow rays' transmittance;
// a homogeneous medium's sigma_t and albedo, and a phase function's g, are factors of the
// throughput, whose d log the replay carries along the path).
//
// Reverse mode, per pixel sample (Sampler(seed, pixel, sample) as pt-mis draws it):
//  1. the primal pass traces the path and returns its radiance L (bit for bit pt-mis's sample);
//  2. the replay traces the same path again from the same random numbers, carrying the adjoint
//     radiance delta = dLoss/dI(pixel) / spp and the radiance still to come, Lr (= L minus what
//     the vertices before added). At vertex k with throughput beta_k, each term it adds,
//     beta_k f Le k (k = |cos| w_mis / pdf, detached), gives
//        dLoss/dtheta += delta . (beta_k Le k df/dtheta + beta_k f k dLe/dtheta),
//     and the continuation, whose weight f |cos| / pdf scales everything after it, gives
//        dLoss/dtheta += delta . (Lr / f) df/dtheta          (Lr after subtracting vertex k's terms).
// Nothing per path is stored: memory is independent of spp and path length. Gradients are
// summed per band of rows, then pairwise over the bands in a fixed tree: the same bytes with any
// thread count.
//
// Forward mode carries a tangent (d beta, d L) along the path for one direction in parameter
// space and gives one image of dI/dtheta per parameter (all its components at once, as
// Mitsuba's dr.forward on a colour).
#pragma once

#include <vector>

#include "diff/parameters.hpp"
#include "image/image.hpp"
#include "integrators/integrator.hpp"

namespace pathlab {

// Test-only fault switches (tests/test_differentiable.cpp shows the tests fail with each).
struct DiffFaults {
    bool drop_glossy_lobe = false;      // Phong's glossy lobe left out of df/dtheta
    bool drop_continuation = false;     // the continuation's term (Lr / f) df/dtheta left out
    bool replay_other_numbers = false;  // the replay draws another sample's random numbers
    bool texel_weights_wrong_corner = false;  // each texel of a bilinear lookup gets the opposite corner's weight
};

struct DiffSettings {
    int width = 64, height = 64;
    uint64_t seed = 1234;
    int spp = 4;
    uint64_t first_pass = 0;  // sample indices first_pass, ..., first_pass + spp - 1
    SamplerKind sampler = SamplerKind::Independent;
    int max_depth = -1;       // bounces, as IntegratorOptions
    int rr_depth = 3;
    bool hide_emitters = false;
    DiffFaults faults = {};  // none, except in tests
};

// pt-mis's image, volpath's in a scene with media (the mean of spp samples per pixel; box filter, pinhole or any camera).
Image render_primal(const Scene& scene, const DiffSettings& s);

// dLoss/dtheta for the set's theta, where adjoint(x, y) = dLoss/dI(x, y) (the image is the mean
// of spp samples, as render_primal's).
std::vector<double> gradient(const Scene& scene, const ParameterSet& set, const DiffSettings& s, const Image& adjoint);

// Forward mode: the image dI/dtheta along `tangent` (a direction in theta, set.size floats).
Image forward_gradient(const Scene& scene, const ParameterSet& set, const DiffSettings& s, const std::vector<float>& tangent);
// The tangent that moves every component of parameter i of the set by 1.
std::vector<float> parameter_tangent(const ParameterSet& set, size_t i);

}  // namespace pathlab
