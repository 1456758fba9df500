// Inverse rendering's loop, shared by `pathlab optimize` and Python's pathlab.optimize: render
// pt-mis's image of theta, its loss against the target, the gradient by path replay (with
// independent samples, so the L2 loss's gradient is unbiased), one optimiser step, clamp to the
// parameters' ranges; repeat.
#pragma once

#include <functional>
#include <vector>

#include "diff/loss.hpp"
#include "diff/optimizer.hpp"
#include "diff/path_replay.hpp"

namespace pathlab {

struct OptimizationSettings {
    DiffSettings render;  // size, spp, seed, depth of every image
    Loss loss;
    OptimizerKind optimizer = OptimizerKind::Adam;
    double learning_rate = 0.02;
    int iterations = 50;
    bool seed_per_iteration = false;  // new random numbers every iteration (default: the same ones; always with a medium's sigma_t)
};

// The chosen parameter that is a medium's extinction (whose optimisation always draws new random
// numbers every iteration), or null.
const SceneParameter* extinction_parameter(const ParameterSet& set);

// One iteration, before its step: theta as rendered, the image, its loss and the gradient.
struct OptimizationStep {
    int iteration;
    const std::vector<float>& theta;
    const Image& image;
    double loss;
    const std::vector<double>& gradient;
};

struct OptimizationResult {
    std::vector<float> theta;  // after the last step (stopped early: of the lowest loss seen)
    std::vector<float> best;   // of the lowest loss seen
    double best_loss;
    int iterations;  // rendered and reported to `each` (the one it stopped at included)
    bool stopped;    // `each` asked to stop
};

// Runs the loop on a copy of `d`, from the set's values in it; `each` is called every iteration
// and returns false to stop (an interrupt).
OptimizationResult optimize(const SceneDescription& d, const ParameterSet& set, const Image& target, const OptimizationSettings& s,
                            const std::function<bool(const OptimizationStep&)>& each);

}  // namespace pathlab
