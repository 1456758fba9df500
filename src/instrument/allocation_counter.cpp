#include "instrument/allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
thread_local uint64_t t_allocations = 0;
std::atomic<uint64_t> g_allocations{0};

void* counted_allocation(std::size_t size) {
    ++t_allocations;
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
}  // namespace

namespace pathlab {
uint64_t allocations_by_this_thread() { return t_allocations; }
uint64_t allocations_by_all_threads() { return g_allocations.load(); }
}  // namespace pathlab

// The replaceable global allocation functions. Aligned and nothrow forms keep their default
// definitions, which in libstdc++ route through these or through aligned_alloc (not counted).
void* operator new(std::size_t size) { return counted_allocation(size); }
void* operator new[](std::size_t size) { return counted_allocation(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
