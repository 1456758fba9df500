// mmlt: multiplexed Metropolis light transport over bdpt's strategies (mmlt.cpp says how).
#pragma once

#include <utility>
#include <vector>

#include "integrators/bidir/bdpt.hpp"
#include "integrators/mlt/markov_chains.hpp"

namespace pathlab {

template <class T>
class Mmlt final : public Integrator {
public:
    explicit Mmlt(const IntegratorOptions& o, ChainFaults faults = {});
    void prepare(const RenderContext& ctx, const PassProgress& progress) override;
    PassCounters render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) override;
    std::vector<IntegratorStatistic> statistics() const override { return chains_.statistics(); }

    // The path of a state's numbers at the path length of its label; `chain`'s subpath buffers.
    ChainSample evaluate(const RenderContext& ctx, PrimarySamples& state, int chain);

private:
    static IntegratorOptions bdpt_options(IntegratorOptions o);
    void make_subpaths();  // one camera and one light subpath per chain, at their longest

    IntegratorOptions options_;
    Bdpt<T> bdpt_;  // the subpaths, the connections and their MIS weights
    int first_length_, lengths_;  // the chains' path lengths (bounces): first_length_ + label, label < lengths_
    MarkovChains chains_;
    ChainFaults faults_;
    std::vector<std::pair<typename Bdpt<T>::Subpath, typename Bdpt<T>::Subpath>> subpaths_;  // per chain: camera, light
};
extern template class Mmlt<RgbTransport>;
extern template class Mmlt<SpectralTransport>;

}  // namespace pathlab
