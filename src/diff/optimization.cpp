#include "diff/optimization.hpp"

#include <limits>
#include <memory>

#include "scene/scene.hpp"

namespace pathlab {

const SceneParameter* extinction_parameter(const ParameterSet& set) {
    for (const SceneParameter& p : set.params)
        if (p.field == ParamField::MediumSigmaT) return &p;
    return nullptr;
}

OptimizationResult optimize(const SceneDescription& d, const ParameterSet& set, const Image& target, const OptimizationSettings& s,
                            const std::function<bool(const OptimizationStep&)>& each) {
    SceneDescription desc = d;
    Optimizer opt(s.optimizer, s.learning_rate, size_t(set.size));
    OptimizationResult r{set.values(desc), {}, std::numeric_limits<double>::infinity(), 0, false};
    // A medium's extinction moves the free flights themselves: its gradient is heavy-tailed (a
    // rare scattering event weighs 1 / sigma_t), and one fixed set of samples can be far off its
    // mean and lead the optimiser away (docs/differentiable.md): new samples every iteration.
    const bool seed_per_iteration = s.seed_per_iteration || extinction_parameter(set) != nullptr;
    r.best = r.theta;
    for (; r.iterations < s.iterations; ++r.iterations) {
        const int it = r.iterations;
        set.set_values(desc, r.theta);
        const std::unique_ptr<Scene> built = Scene::build(desc);
        DiffSettings primal = s.render;
        // The image of the loss and the gradient's replay use independent samples (seeds 2i and
        // 2i + 1 past the seed per iteration).
        primal.seed = s.render.seed + (seed_per_iteration ? 2 * uint64_t(it) : 0);
        const Image image = render_primal(*built, primal);
        const double L = loss_value(image, target, s.loss);
        if (L < r.best_loss) r.best_loss = L, r.best = r.theta;
        DiffSettings replay = primal;
        replay.seed = primal.seed + 1;
        const std::vector<double> g = gradient(*built, set, replay, loss_adjoint(image, target, s.loss));
        if (!each({it, r.theta, image, L, g})) {
            r.stopped = true, r.iterations = it + 1;  // this one was rendered and reported
            r.theta = r.best;
            break;
        }
        opt.step(r.theta, g);
        set.clamp(r.theta);
    }
    return r;
}

}  // namespace pathlab
