#include "core/memory.hpp"

#include <fstream>

#include <fmt/format.h>

namespace pathlab {

uint64_t available_memory() {
    std::ifstream in("/proc/meminfo");
    std::string key, unit;
    uint64_t kib = 0;
    while (in >> key >> kib >> unit)
        if (key == "MemAvailable:") return kib * 1024;
    return 0;
}

void check_memory(uint64_t bytes, const std::string& what, const std::string& advice) {
    const uint64_t available = available_memory();
    if (available > 0 && bytes > available)
        throw NotEnoughMemory(fmt::format("{} would need {:.1f} GiB of memory, but only {:.1f} GiB is available{}", what, gib(bytes),
                                          gib(available), advice));
}

}  // namespace pathlab
