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

void check_memory(double bytes, const std::function<std::string()>& what, const std::function<std::string(uint64_t)>& advice) {
    const uint64_t available = available_memory();
    if (available == 0 || bytes <= double(available)) return;
    throw NotEnoughMemory(fmt::format("{} would need {:.1f} GiB of memory, but only {:.1f} GiB is available{}", what(),
                                      bytes / double(uint64_t(1) << 30), gib(available), advice ? advice(available) : ""));
}

}  // namespace pathlab
