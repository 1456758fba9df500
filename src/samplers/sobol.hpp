// The first two dimensions of the Sobol sequence, Owen-scrambled with a hash, and shuffled in
// sample order, as in Burley, "Practical Hash-based Owen Scrambling" (JCGT 2020). The two
// dimensions form a (0,2)-sequence in base 2: every power-of-two prefix of 2^m points is a
// (0,m,2)-net (one point in each elementary interval of area 2^-m); Owen scrambling and the
// index shuffle keep that while making the points a random, unbiased sample.
#pragma once

#include <bit>
#include <cstdint>

namespace pathlab {

inline uint32_t reverse_bits(uint32_t x) {
    x = __builtin_bswap32(x);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
}

// A hash that only propagates bits upwards (each output bit depends on itself and lower input
// bits): on bit-reversed values it acts as a nested uniform (Owen) scramble. Constants from
// Burley's paper.
inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Owen scrambling of a 32-bit fixed-point value in [0, 1) (most significant bit first).
inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
    return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

// Sobol dimension 0 (van der Corput) and dimension 1 (primitive polynomial x + 1, whose
// direction numbers satisfy v_{k+1} = v_k ^ (v_k >> 1)), as 32-bit fractions. Dimension 1 is
// the XOR of the direction numbers of the index's set bits, taken a byte at a time from tables
// (shuffled indices use all 32 bits, so a bit-by-bit loop would cost 32 steps).
inline uint32_t sobol_dimension0(uint32_t index) { return reverse_bits(index); }

namespace detail {
struct SobolDimension1Tables {
    uint32_t byte[4][256];
    constexpr SobolDimension1Tables() : byte{} {
        uint32_t v[32] = {};
        v[0] = 1u << 31;
        for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        for (int b = 0; b < 4; ++b)
            for (uint32_t x = 0; x < 256; ++x)
                for (int j = 0; j < 8; ++j)
                    if (x & (1u << j)) byte[b][x] ^= v[8 * b + j];
    }
};
inline constexpr SobolDimension1Tables kSobolDimension1;
}  // namespace detail

inline uint32_t sobol_dimension1(uint32_t index) {
    const auto& t = detail::kSobolDimension1.byte;
    return t[0][index & 0xff] ^ t[1][(index >> 8) & 0xff] ^ t[2][(index >> 16) & 0xff] ^ t[3][index >> 24];
}

inline float fixed_to_float(uint32_t x) { return float(x >> 8) * 0x1p-24f; }

}  // namespace pathlab
