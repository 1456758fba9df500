// Gradient-based optimisers over a parameter vector theta: Adam (Kingma and Ba 2015, the
// defaults beta1 = 0.9, beta2 = 0.999, epsilon = 1e-8, as Mitsuba 3's) and plain gradient
// descent. The caller clamps theta to the parameters' ranges after each step.
#pragma once

#include <string>
#include <vector>

namespace pathlab {

enum class OptimizerKind { Adam, GradientDescent };
// "adam" or "gd" (std::invalid_argument listing them otherwise).
OptimizerKind parse_optimizer_kind(const std::string& name);

class Optimizer {
public:
    Optimizer(OptimizerKind kind, double learning_rate, size_t size);
    void step(std::vector<float>& theta, const std::vector<double>& gradient);

private:
    OptimizerKind kind_;
    double lr_;
    std::vector<double> m_, v_;
    int t_ = 0;
};

}  // namespace pathlab
