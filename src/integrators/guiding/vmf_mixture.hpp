// A mixture of von Mises-Fisher lobes over the sphere of directions, fitted on-line by weighted
// EM: the directional model of `--guiding vmm` (Vorba, Karlík, Šik, Ritschel and Křivánek,
// "On-line learning of parametric mixture models for light transport simulation", SIGGRAPH 2014).
//
//   a lobe      v(d; mu, kappa) = kappa / (2 pi (1 - e^(-2 kappa))) e^(kappa (mu.d - 1)),
//               a solid-angle density (per steradian) peaked around the unit mean mu;
//   the model   p(d) = sum_k pi_k v(d; mu_k, kappa_k), kLobes lobes, weights pi_k summing to 1.
//
// The fit sees weighted directions (d_i, w_i): w_i = the radiance arriving from d_i over the
// density d_i was drawn with, so that the weighted directions follow the arriving radiance. It is
// stepwise EM (Cappé and Moulines 2009, the on-line EM Vorba et al. use): records are taken in
// batches of kBatch; each batch's sufficient statistics (per lobe: sum w gamma and sum w gamma d,
// gamma the lobe's responsibility under the mixture before the batch, over the mean weight of the
// batches so far) are blended into the running ones with step size
// eta_t = (t + 1)^(-kStepExponent) (t: batches before), and the M-step turns the running
// statistics into the mixture:
//   pi_k = s0_k / sum s0,   mu_k = s1_k / |s1_k|,   r_k = |s1_k| / s0_k (the mean cosine),
//   kappa_k = r (3 - r^2) / (1 - r^2) (Banerjee et al. 2005's approximation),
// with the maximum a posteriori priors that keep a lobe seen by few directions broad (r pulled to
// 0 by kMeanCosinePrior virtual directions, as Open PGL's meanCosinePriorStrength does) and every
// lobe alive (pi_k >= kWeightPrior / kLobes). The records are taken in a fixed order, so the fit
// is deterministic. The lobe count is fixed (no split and merge of lobes, unlike Open PGL's).
#pragma once

#include <array>
#include <cstdint>

#include "core/vec.hpp"

namespace pathlab {

struct VmfLobe {
    Vec3f mean{0.0f, 0.0f, 1.0f};
    float kappa = 0;   // 0: uniform over the sphere
    float weight = 0;  // pi_k

    float pdf(const Vec3f& d) const;   // per steradian
    Vec3f sample(Vec2f u) const;       // a direction with density pdf()
};

class VmfMixture {
public:
    static constexpr int kLobes = 8;
    static constexpr float kInitialKappa = 2.0f;

    // The untrained mixture: kLobes broad lobes, equal weights, means at the cube's corners.
    VmfMixture();
    float pdf(const Vec3f& d) const;  // per steradian, integrating to 1 over the sphere
    // Each lobe's weighted density pi_k v(d; mu_k, kappa_k) (summing to pdf(d)).
    std::array<float, kLobes> weighted_lobe_pdfs(const Vec3f& d) const;
    Vec3f sample(Vec2f u) const;      // a direction with density pdf() (r in [0, 1)^2)
    const std::array<VmfLobe, kLobes>& lobes() const { return lobes_; }
    void set_lobe(int k, const VmfLobe& lobe);

private:
    std::array<VmfLobe, kLobes> lobes_;
    // Per lobe pi_k times v's normalisation, and the kappa of its exponent (0 for a uniform lobe):
    // a density is then one exponential per lobe.
    std::array<float, kLobes> scale_{}, kappa_{};
};

class VmfMixtureFit {
public:
    static constexpr int kBatch = 64;
    static constexpr float kStepExponent = 0.6f;
    static constexpr float kMeanCosinePrior = 8.0f;  // virtual directions of mean cosine 0 per lobe
    static constexpr float kWeightPrior = 0.01f;
    static constexpr float kMaxMeanCosine = 0.9999f;  // kappa at most about 5000

    // Adds a weighted direction (weights <= 0 or not finite are left out).
    void add(const Vec3f& d, float weight);
    // Takes the partial batch too (at the end of a training iteration).
    void flush();
    const VmfMixture& mixture() const { return mixture_; }
    uint64_t directions() const { return directions_; }  // the directions taken (weight > 0)

private:
    void step();

    VmfMixture mixture_;
    // The running statistics (per unit of weight), and the batch's sums.
    std::array<double, VmfMixture::kLobes> s0_{};
    std::array<std::array<double, 3>, VmfMixture::kLobes> s1_{};
    std::array<double, VmfMixture::kLobes> batch0_{};
    std::array<std::array<double, 3>, VmfMixture::kLobes> batch1_{};
    double batch_weight_ = 0, weight_sum_ = 0;  // this batch's weight, all batches'

    int batch_count_ = 0;
    uint32_t steps_ = 0;
    uint64_t directions_ = 0;
};

}  // namespace pathlab
