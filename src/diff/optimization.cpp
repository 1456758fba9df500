#include "diff/optimization.hpp"

#include <limits>
#include <memory>

#include "scene/scene.hpp"

namespace pathlab {

OptimizationResult optimize(const SceneDescription& d, const ParameterSet& set, const Image& target, const OptimizationSettings& s,
                            const std::function<bool(const OptimizationStep&)>& each) {
    SceneDescription desc = d;
    Optimizer opt(s.optimizer, s.learning_rate, size_t(set.size));
    OptimizationResult r{set.values(desc), {}, std::numeric_limits<double>::infinity(), 0, false};
    r.best = r.theta;
    for (; r.iterations < s.iterations; ++r.iterations) {
        const int it = r.iterations;
        set.set_values(desc, r.theta);
        const std::unique_ptr<Scene> built = Scene::build(desc);
        DiffSettings primal = s.render;
        // The image of the loss and the gradient's replay use independent samples (seeds 2i and
        // 2i + 1 past the seed per iteration).
        primal.seed = s.render.seed + (s.seed_per_iteration ? 2 * uint64_t(it) : 0);
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
