#include "diff/optimizer.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace pathlab {

OptimizerKind parse_optimizer_kind(const std::string& name) {
    if (name == "adam") return OptimizerKind::Adam;
    if (name == "gd") return OptimizerKind::GradientDescent;
    throw std::invalid_argument(fmt::format("unknown optimizer '{}'; valid: adam, gd", name));
}

Optimizer::Optimizer(OptimizerKind kind, double learning_rate, size_t size)
    : kind_(kind), lr_(learning_rate), m_(size, 0.0), v_(size, 0.0) {}

void Optimizer::step(std::vector<float>& theta, const std::vector<double>& g) {
    ++t_;
    constexpr double b1 = 0.9, b2 = 0.999, eps = 1e-8;
    for (size_t i = 0; i < theta.size(); ++i) {
        if (kind_ == OptimizerKind::GradientDescent) {
            theta[i] = float(theta[i] - lr_ * g[i]);
            continue;
        }
        m_[i] = b1 * m_[i] + (1 - b1) * g[i];
        v_[i] = b2 * v_[i] + (1 - b2) * g[i] * g[i];
        const double mh = m_[i] / (1 - std::pow(b1, t_)), vh = v_[i] / (1 - std::pow(b2, t_));
        theta[i] = float(theta[i] - lr_ * mh / (std::sqrt(vh) + eps));
    }
}

}  // namespace pathlab
