// Random number generation: a 64-bit mixer for deriving stream seeds, and PCG32.
#pragma once

#include <cstdint>


namespace pathlab {

// SplitMix64 finaliser: a bijective 64-bit mixer used to derive independent stream seeds.
constexpr uint64_t mix64(uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// PCG32 (O'Neill 2014): 64-bit LCG state, xorshift-rotate output.
class Pcg32 {
public:
    Pcg32(uint64_t seed, uint64_t stream) : inc_((stream << 1u) | 1u) {
        next_u32();
        state_ += seed;
        next_u32();
    }
    uint32_t next_u32() {
        const uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        const auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((-rot) & 31u));
    }
    // Uniform in [0, 1): 24 random mantissa bits, so 1.0f is never returned.
    float next_float() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }

private:
    uint64_t state_ = 0;
    uint64_t inc_;
};

}  // namespace pathlab
