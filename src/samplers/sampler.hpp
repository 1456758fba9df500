// The random numbers of one path sample. A sample's stream is a pure function of (seed, pixel,
// sample index), so an image does not depend on thread count, tile order or how a render is
// split into parts.
#pragma once

#include <cstdint>

#include "core/rng.hpp"
#include "core/vec.hpp"
#include "samplers/primary_samples.hpp"
#include "samplers/sobol.hpp"
#include <vector>

#include "core/properties.hpp"

namespace pathlab {

enum class SamplerKind {
    Independent,  // PCG32 numbers: independent samples (the course's estimators, the tests)
    Sobol,        // padded, shuffled, Owen-scrambled 2D Sobol points (lower error, see sobol.hpp)
    Primary,      // the numbers of a Markov chain's state (primary_samples.hpp: pssmlt)
};

// The random numbers of one path sample. With SamplerKind::Sobol, the k-th call of next1d() or
// next2d() (a "dimension" of the path) takes the sample's point from a (0,2)-sequence that is
// shuffled and scrambled independently per pixel and per dimension, so that each dimension on
// its own is stratified across the pixel's samples while different dimensions stay
// uncorrelated (padding). Samples stay a pure function of (seed, pixel, sample index).
class Sampler {
public:
    Sampler(uint64_t seed, uint64_t pixel_index, uint64_t sample_index, SamplerKind kind = SamplerKind::Independent)
        : rng_(mix64(mix64(seed ^ mix64(pixel_index)) + sample_index), mix64(seed + 0x5bd1e995ull * pixel_index)),
          kind_(kind),
          reversed_index_(reverse_bits(uint32_t(sample_index))),
          pixel_hash_(mix64(seed ^ mix64(pixel_index ^ 0x243f6a8885a308d3ull))) {}

    // The numbers of a primary-sample-space state's stream, in the order the path reads them.
    explicit Sampler(PrimarySamples& state, int stream = 0)
        : rng_(0, 0), kind_(SamplerKind::Primary), reversed_index_(0), dimension_(uint32_t(stream)), pixel_hash_(0), state_(&state) {}

    float next1d() {
        if (kind_ == SamplerKind::Independent) return rng_.next_float();
        if (kind_ == SamplerKind::Primary) return state_->next1d(int(dimension_));
        const uint64_t h = dimension_hash();
        return fixed_to_float(scrambled_dimension0(shuffled_index(uint32_t(h)), uint32_t(h >> 32)));
    }
    Vec2f next2d() {
        if (kind_ == SamplerKind::Independent) {
            const float a = rng_.next_float();
            return {a, rng_.next_float()};
        }
        if (kind_ == SamplerKind::Primary) return state_->next2d(int(dimension_));
        const uint64_t h = dimension_hash();
        const uint32_t i = shuffled_index(uint32_t(h));
        const uint32_t seed1 = uint32_t((h * 0xd1342543de82ef95ull) >> 32);  // a third seed
        return {fixed_to_float(scrambled_dimension0(i, uint32_t(h >> 32))),
                fixed_to_float(nested_uniform_scramble(sobol_dimension1(i), seed1))};
    }

    // Another stream of the same sample, keyed by `stream` (same kind, its own dimensions):
    // what an integrator draws there does not shift this stream's dimensions. volpath draws
    // its free-flight distances there, so that a path through no medium uses exactly the
    // numbers pt-mis uses. (Keyed by the sample index's low 32 bits.)
    // A primary-sample-space sampler's fork reads on from the same state and stream.
    Sampler fork(uint64_t stream) const {
        if (kind_ == SamplerKind::Primary) return Sampler(*state_, int(dimension_));
        return Sampler(pixel_hash_, stream, reverse_bits(reversed_index_), kind_);
    }

private:
    uint64_t dimension_hash() { return mix64(pixel_hash_ + 0x9e3779b97f4a7c15ull * ++dimension_); }
    // nested_uniform_scramble(index, seed), with the index's bit reversal done once.
    uint32_t shuffled_index(uint32_t seed) const { return reverse_bits(laine_karras_permutation(reversed_index_, seed)); }
    // nested_uniform_scramble(sobol_dimension0(i), seed): the two bit reversals cancel.
    static uint32_t scrambled_dimension0(uint32_t i, uint32_t seed) { return reverse_bits(laine_karras_permutation(i, seed)); }

    Pcg32 rng_;
    SamplerKind kind_;
    uint32_t reversed_index_;  // bit-reversed sample index
    uint32_t dimension_ = 0;  // (Primary: the state's stream)
    uint64_t pixel_hash_;
    PrimarySamples* state_ = nullptr;
};

// The scene-file samplers (Mitsuba's independent, stratified, ...): their sample count is the
// render's default spp; the pattern is pathlab's, chosen with --sampler (independent or sobol),
// so a file's other sampler types and their pattern parameters are accepted with a note.
inline const PluginInfo& independent_plugin() {
    static const PluginInfo info{"sampler", "independent", "the number of samples per pixel",
                                 {{"sample_count", ParamType::Integer, "4", "samples per pixel (--spp wins)", "sampleCount"},
                                  {"seed", ParamType::Integer, "0", "accepted and ignored: pathlab's --seed sets the random numbers"}}};
    return info;
}
inline const std::vector<PluginInfo>& other_sampler_plugins() {
    static const std::vector<PluginInfo> plugins = [] {
        std::vector<PluginInfo> out;
        const ParamInfo count{"sample_count", ParamType::Integer, "4", "samples per pixel (--spp wins)", "sampleCount"};
        const ParamInfo seed{"seed", ParamType::Integer, "0", "accepted and ignored: pathlab's --seed sets the random numbers"};
        const ParamInfo jitter{"jitter", ParamType::Boolean, "true", "accepted and ignored (the pattern is pathlab's)"};
        const ParamInfo scramble{"scramble", ParamType::Integer, "-1", "accepted and ignored (the pattern is pathlab's)"};
        const ParamInfo strength{"strength", ParamType::Integer, "2", "accepted and ignored (the pattern is pathlab's)"};
        for (const char* type : {"stratified", "multijitter", "orthogonal", "ldsampler", "halton", "hammersley", "sobol"})
            out.push_back({"sampler", type, "accepted as independent: its sample_count counts, its pattern is pathlab's --sampler (with a note)",
                           {count, seed, jitter, scramble, strength}});
        return out;
    }();
    return plugins;
}

}  // namespace pathlab
