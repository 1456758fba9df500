// pssmlt: primary-sample-space Metropolis light transport over pt-mis (pssmlt.cpp says how).
#pragma once

#include <atomic>
#include <vector>

#include "integrators/common/path_rules.hpp"
#include "integrators/integrator.hpp"
#include "render/pass_image.hpp"
#include "samplers/primary_samples.hpp"

namespace pathlab {

// The scalar contribution I a chain follows: the luminance weights over |R|, |G|, |B| (zero only
// for a black path, so every path that carries light can be visited).
double mlt_contribution(const Vec3d& film_colour);

// Deliberate errors, for the tests of the tests.
struct PssmltFaults {
    bool drop_current_weight = false;  // splat the proposals only, without the current state's (1 - a) / I(X)
};

template <class T>
class Pssmlt final : public Integrator {
public:
    explicit Pssmlt(const IntegratorOptions& o, PssmltFaults faults = {});
    void prepare(const RenderContext& ctx, const PassProgress& progress) override;
    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) override;
    std::vector<IntegratorStatistic> statistics() const override;

    // A path made from a state's numbers: where it lands, its colour (the film's linear RGB) and I.
    struct PathSample {
        Vec2f raster;
        Vec3d colour{0.0};
        double contribution = 0;
        bool invalid = false;  // NaN or infinite (counted, and black)
    };
    PathSample evaluate(const RenderContext& ctx, PrimarySamples& state) const;

private:
    // Pass `pass`'s bootstrap: n independent paths (a pass's: --bootstrap), their running sum of
    // I in `cumulative`; returns b^, their mean I.
    double bootstrap(const RenderContext& ctx, uint64_t pass, int n, std::vector<double>& cumulative, uint64_t& invalid,
                     std::atomic<uint64_t>& rays);

    // One state per chain (min(--chains, pixels)), kept from pass to pass.
    void make_states(const RenderContext& ctx);

    IntegratorOptions options_;
    PathRules rules_;
    PssmltFaults faults_;
    std::vector<PrimarySamples> states_;  // one per chain, kept from pass to pass (no allocation once warm)
    std::vector<double> weights_, cumulative_;
    PassImage pass_;
    double normalisation_ = 0;  // b from prepare()'s bootstrap (the metadata's)
    uint64_t accepted_ = 0, proposed_ = 0;  // mutations, for the acceptance rate
};
extern template class Pssmlt<RgbTransport>;
extern template class Pssmlt<SpectralTransport>;

}  // namespace pathlab
