#include "integrators/guiding/vmf_mixture.hpp"

#include <algorithm>
#include <cmath>

#include "core/frame.hpp"
#include "core/sampling.hpp"

namespace pathlab {

namespace {

constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;
constexpr float kUniformKappa = 1e-4f;  // below it a lobe is sampled and evaluated as uniform

}  // namespace

float VmfLobe::pdf(const Vec3f& d) const {
    if (kappa < kUniformKappa) return uniform_sphere_pdf();
    // kappa / (2 pi (1 - e^(-2 kappa))) e^(kappa (mu.d - 1)): the normalisation without overflow.
    return kappa / (2.0f * kPi * -std::expm1(-2.0f * kappa)) * std::exp(kappa * (std::min(dot(mean, d), 1.0f) - 1.0f));
}

Vec3f VmfLobe::sample(Vec2f u) const {
    if (kappa < kUniformKappa) return square_to_uniform_sphere(u);
    // The cosine to the mean by inverting its distribution, e^(kappa (c - 1)) on [-1, 1]:
    // c = 1 + log(u + (1 - u) e^(-2 kappa)) / kappa.
    const float x = std::max(u.x, 1e-30f);
    const float c = std::clamp(1.0f + std::log(x + (1.0f - x) * std::exp(-2.0f * kappa)) / kappa, -1.0f, 1.0f);
    const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
    const float phi = 2.0f * kPi * u.y;
    return normalize(Frame(mean).to_world(Vec3f(s * std::cos(phi), s * std::sin(phi), c)));
}

VmfMixture::VmfMixture() {
    for (int k = 0; k < kLobes; ++k) {
        const Vec3f corner(k & 1 ? 1.0f : -1.0f, k & 2 ? 1.0f : -1.0f, k & 4 ? 1.0f : -1.0f);
        set_lobe(k, {normalize(corner), kInitialKappa, 1.0f / float(kLobes)});
    }
}

void VmfMixture::set_lobe(int k, const VmfLobe& lobe) {
    const size_t i = size_t(k);
    lobes_[i] = lobe;
    const bool uniform = lobe.kappa < kUniformKappa;
    kappa_[i] = uniform ? 0.0f : lobe.kappa;
    scale_[i] = lobe.weight * (uniform ? uniform_sphere_pdf() : lobe.kappa / (2.0f * kPi * -std::expm1(-2.0f * lobe.kappa)));
}

std::array<float, VmfMixture::kLobes> VmfMixture::weighted_lobe_pdfs(const Vec3f& d) const {
    std::array<float, kLobes> p;
    for (size_t k = 0; k < size_t(kLobes); ++k) p[k] = scale_[k] * std::exp(kappa_[k] * (std::min(dot(lobes_[k].mean, d), 1.0f) - 1.0f));
    return p;
}

float VmfMixture::pdf(const Vec3f& d) const {
    float sum = 0;
    for (const float p : weighted_lobe_pdfs(d)) sum += p;
    return sum;
}

Vec3f VmfMixture::sample(Vec2f u) const {
    // The lobe by its weight (u.x reused, stretched back to [0, 1)), then a direction from it.
    float cdf = 0;
    for (int k = 0; k < kLobes; ++k) {
        const VmfLobe& l = lobes_[size_t(k)];
        if (u.x < cdf + l.weight || k == kLobes - 1) {
            u.x = l.weight > 0 ? std::clamp((u.x - cdf) / l.weight, 0.0f, kOneMinusEpsilon) : 0.0f;
            return l.sample(u);
        }
        cdf += l.weight;
    }
    return lobes_.back().sample(u);
}

void VmfMixtureFit::add(const Vec3f& d, float weight) {
    if (!(weight > 0) || !std::isfinite(weight)) return;
    ++directions_;
    // The responsibilities of the lobes of the mixture before this batch.
    const std::array<float, VmfMixture::kLobes> gamma = mixture_.weighted_lobe_pdfs(d);
    float total = 0;
    for (const float g : gamma) total += g;
    if (!(total > 0)) return;
    for (int k = 0; k < VmfMixture::kLobes; ++k) {
        const double g = double(weight) * double(gamma[size_t(k)] / total);
        batch0_[size_t(k)] += g;
        for (int a = 0; a < 3; ++a) batch1_[size_t(k)][size_t(a)] += g * double(d[a]);
    }
    batch_weight_ += weight;
    if (++batch_count_ == kBatch) step();
}

void VmfMixtureFit::flush() {
    if (batch_count_ > 0) step();
}

void VmfMixtureFit::step() {
    const double eta = std::pow(double(steps_) + 1.0, -double(kStepExponent));  // 1 at the first batch
    // Per unit of the mean batch weight so far, not of this batch's own: a batch that found
    // more light counts for more (with its own weight as the unit, the many batches that miss a
    // small bright lobe would each outvote the one that found it).
    weight_sum_ += batch_weight_;
    ++steps_;
    const double unit = weight_sum_ / double(steps_);
    for (int k = 0; k < VmfMixture::kLobes; ++k) {
        const size_t i = size_t(k);
        s0_[i] = (1 - eta) * s0_[i] + eta * batch0_[i] / unit;
        for (size_t a = 0; a < 3; ++a) s1_[i][a] = (1 - eta) * s1_[i][a] + eta * batch1_[i][a] / unit;
    }
    batch0_ = {}, batch1_ = {}, batch_weight_ = 0, batch_count_ = 0;
    // The M-step, with the priors (vmf_mixture.hpp).
    double s0_sum = 0;
    for (double s : s0_) s0_sum += s;
    if (!(s0_sum > 0)) return;
    constexpr float kFloor = kWeightPrior / float(VmfMixture::kLobes);
    for (int k = 0; k < VmfMixture::kLobes; ++k) {
        const size_t i = size_t(k);
        VmfLobe l = mixture_.lobes()[i];
        l.weight = float(s0_[i] / s0_sum) * (1.0f - kWeightPrior) + kFloor;
        const double length_s1 = std::sqrt(s1_[i][0] * s1_[i][0] + s1_[i][1] * s1_[i][1] + s1_[i][2] * s1_[i][2]);
        if (s0_[i] > 0 && length_s1 > 0) {  // (a lobe no direction reached keeps its shape)
            l.mean = normalize(Vec3f(float(s1_[i][0]), float(s1_[i][1]), float(s1_[i][2])));
            // The mean cosine, pulled towards 0 by the prior's virtual directions (n: the directions the lobe took).
            const double n = s0_[i] / s0_sum * double(directions_);
            const float r = std::min(float(length_s1 / s0_[i] * n / (n + double(kMeanCosinePrior))), kMaxMeanCosine);
            l.kappa = r * (3.0f - r * r) / (1.0f - r * r);
        }
        mixture_.set_lobe(k, l);
    }
}

}  // namespace pathlab
