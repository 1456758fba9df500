// An order-independent sum of doubles: the film's accumulator.
//
// Why: a render split into parts (several processes, a resumed checkpoint, a merge) adds the
// same per-pass values in another grouping, and floating-point addition is not associative:
// ((a + b) + c) + d and (a + b) + (c + d) differ in their last bits, and the standard error,
// which subtracts two nearly equal sums, magnifies that. So the film does not add doubles: it
// adds integers, exactly, and the result depends only on the set of values added.
//
// How (the "binned" idea of Demmel and Nguyen's reproducible summation, with integer bins):
// every double is a multiple of 2^-1074, i.e. an integer in a fixed-point frame 2^-1080. That
// frame is cut into bins of kBinBits = 30 bits at fixed positions. An accumulator keeps three
// consecutive bins, the highest (`top`) being the bin of the largest value added so far, each
// bin an int64 that sums the 30-bit slices of the values falling into it. The bits of a value
// below the lowest kept bin are dropped (truncated towards zero). When a larger value arrives,
// the window moves up and the lowest bins are dropped whole; since bins sit at fixed
// positions, what is dropped is exactly what depositing every value with the final window
// would have dropped. Hence the state is a function of the values' multiset only: any order,
// any grouping (merge) gives the same bits.
//
// Precision: the window spans 90 bits and the largest value's leading bit lies in the top bin,
// so every value keeps its bits down to at least 2^-60 of the largest value (a double has 53):
// float samples, whose squares have 48 bits, are summed exactly unless they span more than
// 2^12 in magnitude, and then lose bits below 2^-60 of the largest. The result is read out
// correctly rounded to a double. Capacity: each bin adds slices below 2^30 in an int64, so
// 2^33 values (8.6 billion samples of one pixel) fit.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

namespace pathlab::exact {

constexpr int kBinBits = 30;
constexpr int kBins = 3;
// The fixed-point frame: bit position 0 has weight 2^-kFrame (below the smallest double, 2^-1074).
constexpr int kFrame = 1080;
constexpr uint64_t kSliceMask = (uint64_t(1) << kBinBits) - 1;

// An accumulator is kBins int64 limbs and a byte `top`: limbs[k] sums the slices of bin
// top - 1 - k (bins are numbered from 0 and stored + 1); top = 0 while only zeros were added.

// Moves the window up so that its highest bin is new_top (stored), dropping bins below it.
inline void raise_window(int64_t* limbs, uint8_t& top, int new_top) {
    const int shift = new_top - int(top);
    for (int k = kBins - 1; k >= 0; --k) limbs[k] = k >= shift ? limbs[k - shift] : 0;
    top = uint8_t(new_top);
}

// Adds x (finite) to the accumulator (limbs[kBins], top).
inline void deposit(int64_t* limbs, uint8_t& top, double x) {
    const uint64_t bits = std::bit_cast<uint64_t>(x);
    uint64_t e = (bits >> 52) & 0x7ff, m = bits & ((uint64_t(1) << 52) - 1);
    if (e == 0) {
        if (m == 0) return;
        e = 1;  // subnormal: no implicit bit
    } else {
        m |= uint64_t(1) << 52;
    }
    // |x| = m 2^(e - 1075): its bit 0 sits at position e - 1075 + kFrame of the frame.
    const int p0 = int(e) - 1075 + kFrame;
    const int bin = (p0 + 52) / kBinBits + 1;  // the (stored) bin of the mantissa's top bit
    if (bin > int(top)) raise_window(limbs, top, bin);
    const int shift = p0 - kBinBits * (int(top) - kBins);  // m's position in the window (< 90 - 52)
    unsigned __int128 v;
    if (shift >= 0) v = static_cast<unsigned __int128>(m) << shift;
    else if (shift > -64) v = m >> -shift;
    else return;  // below the window: nothing is kept
    const int64_t s0 = int64_t(uint64_t(v >> (2 * kBinBits))), s1 = int64_t(uint64_t(v >> kBinBits) & kSliceMask),
                  s2 = int64_t(uint64_t(v) & kSliceMask);
    if (bits >> 63) limbs[0] -= s0, limbs[1] -= s1, limbs[2] -= s2;
    else limbs[0] += s0, limbs[1] += s1, limbs[2] += s2;
}

// Adds another accumulator's state (the union of the two sets of values).
inline void merge(int64_t* limbs, uint8_t& top, const int64_t* other_limbs, uint8_t other_top) {
    if (other_top == 0) return;
    if (other_top > top) raise_window(limbs, top, other_top);
    const int shift = int(top) - int(other_top);
    for (int k = shift; k < kBins; ++k) limbs[k] += other_limbs[k - shift];
}

// The sum, correctly rounded to a double.
inline double value(const int64_t* limbs, uint8_t top) {
    if (top == 0) return 0.0;
    // Bins' weights 2^60, 2^30, 1 relative to the lowest; |limbs| < 2^63, so this fits in 124 bits.
    const __int128 total = (static_cast<__int128>(limbs[0]) << (2 * kBinBits)) + (static_cast<__int128>(limbs[1]) << kBinBits) +
                           static_cast<__int128>(limbs[2]);
    return std::ldexp(static_cast<double>(total), kBinBits * (int(top) - kBins) - kFrame);
}

}  // namespace pathlab::exact
