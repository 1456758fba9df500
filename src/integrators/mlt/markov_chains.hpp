// The Markov chains of primary-sample-space Metropolis (pssmlt, mmlt): a bootstrap that
// estimates the normalisation b and starts the chains, the chains' mutations with expected-value
// splatting, and their merge into the film. What a state's numbers make (a pt-mis path, one
// strategy of bdpt) is the integrator's `evaluate`.
//
// The estimate. With b = the integral of the scalar contribution I over the state space, a chain
// whose states X_k are distributed as I / b estimates pixel j's value as (pixels * b / M) *
// sum_k 1_j(X_k) L(X_k) / I(X_k) over M states. Expected-value splatting (Veach's thesis, 11.4):
// at each step both the proposal Y and the current state X are splatted, weighted by the
// acceptance probability a and 1 - a, whichever the chain keeps.
//
// One pass = pixels mutations, spread over --chains chains, so a pass adds one sample of every
// pixel. Each pass is a pure function of (seed, pass): it draws its own bootstrap of --bootstrap
// independent states, estimates b from them and starts every chain from one of them chosen in
// proportion to I (resampling). That start is exact, not only asymptotically: for the pool's
// estimate b^ and a start X_0 resampled from it, E[b^ g(X_0) / I(X_0)] is the integral of g for
// any g, and a kernel that keeps I / b invariant keeps it so for every later state. So every
// pass is an unbiased estimate, passes are independent, and the film's standard errors over
// passes are right (no start-up bias to burn in, no normalisation error that more passes would
// not average out).
//
// Labels (mmlt's path lengths): a state may carry a discrete label in 0..labels-1 that its
// mutations keep. The state space is then the labels times primary sample space, b the sum of
// each label's integral; the bootstrap gives every label the same number of states (b^ = labels
// times their mean I, still exact), and a chain keeps the label of its start.
//
// Chains run in parallel, each splatting into its own list; the lists are added in chain order,
// so the image does not depend on the thread count.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <vector>

#include "integrators/integrator.hpp"
#include "render/pass_image.hpp"
#include "samplers/primary_samples.hpp"

namespace pathlab {

// The scalar contribution I a chain follows: the luminance weights over |R|, |G|, |B| (zero only
// for a black path, so every path that carries light can be visited).
double mlt_contribution(const Vec3d& film_colour);

// A path made from a state's numbers: where it lands, its colour (the film's linear RGB) and I.
struct ChainSample {
    Vec2f raster;
    Vec3d colour{0.0};
    double contribution = 0;
    bool invalid = false;  // NaN or infinite (counted, and black)
};

// A state's path as the chains see it: its film colour at `raster`, and I (NaN or infinite:
// counted, and black).
ChainSample chain_sample(Vec2f raster, const Vec3d& film_colour);
// The raster position of two uniform numbers: anywhere on the image.
Vec2f raster_anywhere(const RenderContext& ctx, Vec2f u);

// Deliberate errors, for the tests of the tests.
struct ChainFaults {
    bool drop_current_weight = false;  // splat the proposals only, without the current state's (1 - a) / I(X)
    bool drop_strategy_count = false;  // mmlt: a strategy's contribution not divided by its probability 1 / n_d
};

class MarkovChains {
public:
    // `streams`: the interleaved number streams of each state; `labels`: as above (1: none).
    MarkovChains(const IntegratorOptions& o, int streams, int labels, ChainFaults faults = {})
        : options_(o), streams_(streams), labels_(labels), faults_(faults) {}

    // `evaluate(ctx, state, chain)` -> ChainSample: the path of the state's numbers (read with
    // Sampler(state, stream)) and label; `chain` (0 to chains() - 1) names the caller's scratch
    // space, used by one thread at a time.
    //
    // b from a bootstrap of its own, 16 times a pass's: the figure the image's metadata states.
    template <class Evaluate>
    void prepare(const RenderContext& ctx, const Evaluate& evaluate) {
        make_states(ctx);
        const int n = int(std::min<int64_t>(int64_t(options_.mlt_bootstrap) * 16, 1 << 24));
        uint64_t invalid = 0;
        std::atomic<uint64_t> rays{0};
        normalisation_ = bootstrap(ctx, kNormalisationPass, n, invalid, rays, evaluate);
    }

    template <class Evaluate>
    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress,
                               const Evaluate& evaluate);

    // The normalisation b (prepare()'s, stated in the metadata) and the acceptance rate.
    std::vector<IntegratorStatistic> statistics() const {
        return {{"mlt normalisation", normalisation_, true}, {"acceptance", proposed_ ? double(accepted_) / double(proposed_) : 0.0}};
    }

private:
    // Streams of the render's numbers, apart from each other and from every pixel's.
    static constexpr uint64_t kBootstrapStream = 0x6d6c742d626f6f74ull;  // "mlt-boot"
    static constexpr uint64_t kChainStream = 0x6d6c742d63686169ull;      // "mlt-chai"
    static constexpr uint64_t kNormalisationPass = ~uint64_t(0);          // prepare()'s bootstrap, for the metadata
    static uint64_t stream_seed(uint64_t seed, uint64_t pass, uint64_t stream) { return mix64(mix64(seed ^ stream) + pass); }

    // One state per chain (min(--chains, pixels)), kept from pass to pass.
    void make_states(const RenderContext& ctx) {
        const size_t chains = std::min<size_t>(size_t(options_.mlt_chains), ctx.pixel_count());
        if (states_.size() != chains) states_.assign(chains, PrimarySamples(options_.mlt_sigma, options_.mlt_large_step, streams_));
    }
    // The bootstrap's size: n rounded up to a multiple of the labels.
    int bootstrap_size(int n) const { return (n + labels_ - 1) / labels_ * labels_; }

    // Pass `pass`'s bootstrap of bootstrap_size(n) independent states (state i has label
    // i % labels), their running sum of I in cumulative_; returns b^.
    template <class Evaluate>
    double bootstrap(const RenderContext& ctx, uint64_t pass, int n, uint64_t& invalid, std::atomic<uint64_t>& rays,
                     const Evaluate& evaluate);

    IntegratorOptions options_;
    int streams_, labels_;
    ChainFaults faults_;
    std::vector<PrimarySamples> states_;  // one per chain, kept from pass to pass (no allocation once warm)
    std::vector<double> weights_, cumulative_;
    PassImage pass_;
    double normalisation_ = 0;
    uint64_t accepted_ = 0, proposed_ = 0;  // mutations, for the acceptance rate
};

template <class Evaluate>
double MarkovChains::bootstrap(const RenderContext& ctx, uint64_t pass, int n, uint64_t& invalid, std::atomic<uint64_t>& rays,
                               const Evaluate& evaluate) {
    n = bootstrap_size(n);
    weights_.resize(size_t(n));
    const uint64_t seed = stream_seed(ctx.seed, pass, kBootstrapStream);
    std::atomic<uint64_t> bad{0};
    // In as many parts as there are chains, each with a chain's state (no allocation once warm).
    const int parts = int(states_.size());
    tbb::parallel_for(tbb::blocked_range<int>(0, parts, 1), [&](const tbb::blocked_range<int>& r) {
        for (int part = r.begin(); part != r.end(); ++part) {
            const uint64_t rays_before = Scene::rays_traced_by_this_thread();
            PrimarySamples& state = states_[size_t(part)];
            uint64_t local_bad = 0;
            for (int i = int(int64_t(n) * part / parts); i < int(int64_t(n) * (part + 1) / parts); ++i) {
                state.restart(seed, uint64_t(i), uint32_t(i % labels_));
                state.start_iteration(true);
                const ChainSample p = evaluate(ctx, state, part);
                local_bad += p.invalid;
                weights_[size_t(i)] = p.contribution;
            }
            bad += local_bad;
            rays += Scene::rays_traced_by_this_thread() - rays_before;
        }
    });
    invalid += bad.load();
    cumulative_.resize(size_t(n));
    double sum = 0;
    for (int i = 0; i < n; ++i) cumulative_[size_t(i)] = sum += weights_[size_t(i)];
    return sum * double(labels_) / double(n);
}

template <class Evaluate>
PassCounters MarkovChains::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress,
                                         const Evaluate& evaluate) {
    const size_t pixels = ctx.pixel_count();
    make_states(ctx);
    const int chains = int(states_.size());
    std::atomic<uint64_t> rays{0}, invalid{0}, accepted{0}, proposed{0};
    const bool filtered = ctx.filter && !ctx.filter->is_box();
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        uint64_t bad = 0;
        const double b = bootstrap(ctx, pass, options_.mlt_bootstrap, bad, rays, evaluate);
        invalid += bad;
        pass_.begin(pixels, chains);
        if (b > 0) {
            // Each path's weight: pixels * b / M with M = pixels mutations in the pass.
            const double scale = b;
            const uint64_t boot_seed = stream_seed(ctx.seed, pass, kBootstrapStream);
            const uint64_t chain_seed = stream_seed(ctx.seed, pass, kChainStream);
            std::atomic<int> chains_done{0};
            tbb::parallel_for(tbb::blocked_range<int>(0, chains, 1), [&](const tbb::blocked_range<int>& range) {
                for (int c = range.begin(); c != range.end(); ++c) {
                    const uint64_t chain_rays_before = Scene::rays_traced_by_this_thread();
                    PrimarySamples& state = states_[size_t(c)];
                    SplatList& out = pass_.chunk(c);
                    const auto splat = [&](const ChainSample& p, double weight) {
                        if (weight <= 0) return;
                        const Rgb v(p.colour * (weight * scale));
                        if (filtered) out.add_at(p.raster, v);
                        else out.add(uint32_t(size_t(p.raster.y) * size_t(ctx.width) + size_t(p.raster.x)), v);
                    };
                    // The start: a bootstrap state chosen in proportion to I, made again from its numbers.
                    Pcg32 pick(chain_seed, uint64_t(c));
                    const double u = double(pick.next_float()) * cumulative_.back();
                    const size_t start = std::min(size_t(std::upper_bound(cumulative_.begin(), cumulative_.end(), u) - cumulative_.begin()),
                                                  cumulative_.size() - 1);
                    state.restart(boot_seed, uint64_t(start), uint32_t(start % size_t(labels_)));
                    state.start_iteration(true);
                    ChainSample x = evaluate(ctx, state, c);
                    state.accept();
                    state.reseed(chain_seed, uint64_t(chains) + uint64_t(c));
                    // This chain's share of the pass's mutations.
                    const size_t steps = pixels / size_t(chains) + (size_t(c) < pixels % size_t(chains) ? 1 : 0);
                    double x_weight = 0;  // X's expected-value weight, splatted when the chain leaves X
                    uint64_t chain_accepted = 0, chain_invalid = 0;
                    for (size_t m = 0; m < steps; ++m) {
                        state.start_iteration();
                        const ChainSample y = evaluate(ctx, state, c);
                        chain_invalid += y.invalid;
                        const double a = y.contribution <= 0 ? 0.0 : x.contribution <= 0 ? 1.0 : std::min(1.0, y.contribution / x.contribution);
                        if (a > 0) splat(y, a / y.contribution);
                        if (a < 1 && !faults_.drop_current_weight) x_weight += (1 - a) / x.contribution;
                        if (double(state.uniform()) < a) {
                            state.accept();
                            splat(x, x_weight);
                            x = y, x_weight = 0;
                            ++chain_accepted;
                        } else {
                            state.reject();
                        }
                    }
                    splat(x, x_weight);
                    accepted += chain_accepted, proposed += steps, invalid += chain_invalid;
                    rays += Scene::rays_traced_by_this_thread() - chain_rays_before;
                    if (progress) progress((double(k) + double(++chains_done) / chains) / count);
                }
            });
        }
        pass_.finish(film, ctx.filter, Vec2f(0.0f, 0.0f));
    }
    accepted_ += accepted.load(), proposed_ += proposed.load();
    return {rays.load(), invalid.load()};
}

}  // namespace pathlab
