// pssmlt: primary-sample-space Metropolis light transport over pt-mis (pssmlt.cpp says how).
#pragma once

#include <memory>
#include <vector>

#include "integrators/common/path_rules.hpp"
#include "integrators/integrator.hpp"
#include "integrators/mlt/markov_chains.hpp"

namespace pathlab {

template <class T>
class Pssmlt final : public Integrator {
public:
    explicit Pssmlt(const IntegratorOptions& o, ChainFaults faults = {});
    void prepare(const RenderContext& ctx, const PassProgress& progress) override;
    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) override;
    std::vector<IntegratorStatistic> statistics() const override { return chains_.statistics(); }

    // The path of a state's numbers.
    ChainSample evaluate(const RenderContext& ctx, PrimarySamples& state) const;

private:
    IntegratorOptions options_;
    PathRules rules_;
    MarkovChains chains_;
    std::unique_ptr<Integrator> volpath_;  // the paths in a scene with media
};
extern template class Pssmlt<RgbTransport>;
extern template class Pssmlt<SpectralTransport>;

}  // namespace pathlab
