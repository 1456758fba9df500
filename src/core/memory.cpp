#include "core/memory.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>

#include <fmt/format.h>

namespace pathlab {

namespace {

// A number from the first line of a file ("max" or unreadable: none).
std::optional<uint64_t> read_number(const char* path) {
    std::ifstream in(path);
    std::string text;
    if (!(in >> text) || text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    return std::stoull(text);
}

// "VmSize:" of this process, in bytes.
uint64_t address_space_in_use() {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("VmSize:", 0) == 0) return std::strtoull(line.c_str() + 7, nullptr, 10) * 1024;
    return 0;
}

}  // namespace

uint64_t available_memory() {
    uint64_t available = 0;
    {
        std::ifstream in("/proc/meminfo");
        std::string key, unit;
        uint64_t kib = 0;
        while (in >> key >> kib >> unit)
            if (key == "MemAvailable:") {
                available = kib * 1024;
                break;
            }
    }
    // The lower of that and what this process may still take: its address-space limit (ulimit
    // -v) less what it has mapped, and its cgroup's memory.max less memory.current (a container,
    // a batch job). Without them, the check passed and the render ended in std::bad_alloc.
    const auto lower = [&](uint64_t limit) { available = available == 0 ? limit : std::min(available, limit); };
    rlimit as{};
    if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
        const uint64_t used = address_space_in_use();
        lower(uint64_t(as.rlim_cur) > used ? uint64_t(as.rlim_cur) - used : 1);
    }
    if (const auto max = read_number("/sys/fs/cgroup/memory.max"))
        if (const auto current = read_number("/sys/fs/cgroup/memory.current")) lower(*max > *current ? *max - *current : 1);
    return available;
}

void check_memory(double bytes, const std::function<std::string()>& what, const std::function<std::string(uint64_t)>& advice) {
    const uint64_t available = available_memory();
    if (available == 0 || bytes <= double(available)) return;
    throw NotEnoughMemory(fmt::format("{} would need {:.1f} GiB of memory, but only {:.1f} GiB is available{}", what(),
                                      bytes / double(uint64_t(1) << 30), gib(available), advice ? advice(available) : ""));
}

}  // namespace pathlab
