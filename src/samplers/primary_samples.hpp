// Primary sample space (Kelemen, Szirmay-Kalos, Antal and Csonka 2002): a path is a function of
// the uniform numbers it draws, and a Markov chain over those numbers mutates them. This is the
// chain's state, a vector of numbers in [0, 1) extended lazily as paths ask for more, with the
// two mutations of Kelemen et al.:
//   large step  every number replaced by a fresh uniform one (an independent proposal);
//   small step  every number moved by a Gaussian of standard deviation sigma, wrapped to [0, 1).
// Both are symmetric, so a proposal Y of the current state X is accepted with probability
// min(1, I(Y) / I(X)) (Metropolis-Hastings).
//
// Lazily: a number is mutated only when a path reads it. One not read since it was last mutated
// has missed the small steps in between (their sum is one Gaussian of sigma sqrt(n)) or an
// accepted large step (then it is a fresh uniform number). A number the current state never read
// is uniform and independent of everything so far, so it is created as a fresh uniform number
// (X's value) and then mutated like the rest: the chain is exactly the one over infinitely many
// numbers. (pbrt-v3's MLTSampler creates them as 0 and mutates from there, which is uniform only
// after many small steps.)
//
// Streams: a state may hold several sequences of numbers (mmlt: the camera subpath's, the light
// subpath's and the connection's), interleaved, so that a path reading more numbers in one does
// not shift the numbers of the others (a small step then changes each subpath a little).
// And a label: a discrete part of the state that the mutations leave alone (mmlt's path length).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/rng.hpp"
#include "core/vec.hpp"

namespace pathlab {

class PrimarySamples {
public:
    PrimarySamples() = default;
    static constexpr int kMaxStreams = 3;
    PrimarySamples(float sigma, float large_step_probability, int streams = 1)
        : sigma_(sigma), large_step_probability_(large_step_probability), streams_(streams) {}

    // An empty state whose numbers will come from the stream (a, b): the first iteration must be
    // a large step (its path is then a path of independent uniform numbers).
    void restart(uint64_t a, uint64_t b, uint32_t label = 0) {
        rng_ = Pcg32(a, b);
        has_spare_ = false;
        numbers_.clear();
        iteration_ = 0, last_large_ = 0;
        large_ = false;
        label_ = label;
    }
    uint32_t label() const { return label_; }
    // The numbers drawn from now on (mutations and new numbers) come from the stream (a, b).
    void reseed(uint64_t a, uint64_t b) {
        rng_ = Pcg32(a, b);
        has_spare_ = false;
    }

    // Begins a proposal: a large step with probability large_step_probability (or when `large`).
    void start_iteration(bool large) {
        ++iteration_;
        large_ = large;
        for (size_t& n : next_) n = 0;
    }
    // Decides large or small from the state's own stream, then begins.
    void start_iteration() { start_iteration(rng_.next_float() < large_step_probability_); }
    bool large_step() const { return large_; }

    // The next number of stream `stream` (0 to streams - 1).
    float next1d(int stream = 0) {
        const size_t index = next_[stream]++ * size_t(streams_) + size_t(stream);
        while (index >= numbers_.size()) {
            // A number the current state never read: X's value is a fresh uniform one.
            numbers_.push_back({rng_.next_float(), 0.0f, iteration_ - 1, 0});
        }
        Number& n = numbers_[index];
        if (n.modified < last_large_) {  // an accepted large step replaced it since
            n.value = rng_.next_float();
            n.modified = last_large_;
        }
        n.backup = n.value, n.backup_modified = n.modified;
        if (large_) {
            n.value = rng_.next_float();
        } else {
            // The small steps it missed and this one: one Gaussian of sigma sqrt(steps).
            const uint64_t steps = iteration_ - n.modified;
            n.value += normal() * (steps == 1 ? sigma_ : sigma_ * std::sqrt(float(steps)));
            n.value -= std::floor(n.value);
            if (n.value >= 1.0f) n.value = 0.0f;  // -tiny wraps to 1 in float
        }
        n.modified = iteration_;
        return n.value;
    }
    Vec2f next2d(int stream = 0) {
        const float a = next1d(stream);
        return {a, next1d(stream)};
    }

    // The proposal becomes the state.
    void accept() {
        if (large_) last_large_ = iteration_;
    }
    // The state stays: every number the proposal changed goes back.
    void reject() {
        for (Number& n : numbers_)
            if (n.modified == iteration_) n.value = n.backup, n.modified = n.backup_modified;
        --iteration_;
    }
    // A uniform number of the chain's own stream (the acceptance test).
    float uniform() { return rng_.next_float(); }
    size_t dimensions() const { return numbers_.size(); }

private:
    struct Number {
        float value, backup;
        uint64_t modified, backup_modified;  // the iteration that last set value (backup)
    };
    // A standard normal number: Box-Muller makes two, the second kept for the next call.
    float normal() {
        if (has_spare_) {
            has_spare_ = false;
            return spare_;
        }
        const float u1 = 1.0f - rng_.next_float(), u2 = rng_.next_float();
        const float r = std::sqrt(-2.0f * std::log(u1));
        spare_ = r * std::sin(6.2831853f * u2), has_spare_ = true;
        return r * std::cos(6.2831853f * u2);
    }

    float sigma_ = 0.01f, large_step_probability_ = 0.3f;
    Pcg32 rng_{0, 0};
    int streams_ = 1;
    std::vector<Number> numbers_;  // stream k's i-th number at i * streams_ + k
    uint64_t iteration_ = 0, last_large_ = 0;
    size_t next_[kMaxStreams] = {};
    uint32_t label_ = 0;
    bool large_ = false;
    float spare_ = 0;
    bool has_spare_ = false;
};

}  // namespace pathlab
