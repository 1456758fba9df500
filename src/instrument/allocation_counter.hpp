// Counts heap allocations made by the calling thread, for the benchmark and the test that check
// the hot path allocates nothing per sample. Linking this (the pathlab_allocation_counter
// library) replaces the global operator new of the binary; the renderer itself never links it.
#pragma once

#include <cstdint>

namespace pathlab {

uint64_t allocations_by_this_thread();
uint64_t allocations_by_all_threads();

}  // namespace pathlab
