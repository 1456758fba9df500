// Memory a render is about to take, checked before it is allocated: a film, a photon map, a
// set of per-strategy images. A request the machine cannot give is refused with the figure and
// what to lower, where a blind allocation would run for minutes and end in std::bad_alloc (or
// the kernel's OOM killer).
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>

namespace pathlab {

// Memory this process can still take: MemAvailable of /proc/meminfo, lowered by its address-space
// limit (ulimit -v) and its cgroup's memory.max; 0 when unknown.
uint64_t available_memory();

// Bytes in GiB, for messages.
inline double gib(uint64_t bytes) { return double(bytes) / double(uint64_t(1) << 30); }

// A render whose film, maps or images do not fit in memory; what() says how much it needs.
struct NotEnoughMemory : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws NotEnoughMemory("<what> would need X GiB of memory, but only Y GiB is available<advice>")
// when `bytes` is more than the machine can give (nothing when that is unknown); `what` and
// `advice` (given the bytes available, e.g. how much of the request fits) are made only then.
void check_memory(double bytes, const std::function<std::string()>& what,
                  const std::function<std::string(uint64_t available)>& advice = {});

}  // namespace pathlab
