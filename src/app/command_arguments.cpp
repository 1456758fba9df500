#include "app/command_arguments.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <limits>
#include <optional>
#include <string_view>
#include <thread>

#include <fmt/format.h>

#include "job/usage_error.hpp"

namespace pathlab {

namespace {

// A whole number of decimal digits only (no sign, no exponent, no spaces), within [lo, hi].
std::optional<uint64_t> parse_whole_number(std::string_view text, uint64_t lo, uint64_t hi) {
    if (text.empty() || text.size() > 20) return std::nullopt;
    uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || ptr != text.data() + text.size() || v < lo || v > hi) return std::nullopt;
    return v;
}

}  // namespace

bool parse_resolution(const std::string& text, int& width, int& height) {
    const size_t x = text.find_first_of("xX");
    if (x == std::string::npos) return false;
    const auto w = parse_whole_number(std::string_view(text).substr(0, x), 1, kMaxResolution);
    const auto h = parse_whole_number(std::string_view(text).substr(x + 1), 1, kMaxResolution);
    if (!w || !h) return false;
    width = int(*w), height = int(*h);
    return true;
}

void parse_resolution_option(const std::string& text, int& width, int& height) {
    width = height = 0;
    if (!text.empty() && !parse_resolution(text, width, height))
        throw UsageError(fmt::format("invalid --resolution '{}': expected WxH with whole numbers from 1 to {}, e.g. 512x512",
                                     text, kMaxResolution));
}

uint64_t parse_seed_option(const std::string& text) {
    const auto v = parse_whole_number(text, 0, std::numeric_limits<uint64_t>::max());
    if (!v)
        throw UsageError(fmt::format("invalid --seed '{}': expected a whole number from 0 to {}", text,
                                     std::numeric_limits<uint64_t>::max()));
    return *v;
}

void add_threads_option(CLI::App& app, int& threads) {
    app.add_option("--threads", threads, fmt::format("Worker threads (default: all cores; at most {} x the cores)", kMaxThreadsPerCore));
}

size_t thread_count_or_cap(int requested) {
    if (requested <= 0) throw UsageError(fmt::format("--threads must be positive, got {}", requested));
    const size_t cores = std::max(1u, std::thread::hardware_concurrency());
    const size_t cap = kMaxThreadsPerCore * cores;
    if (size_t(requested) <= cap) return size_t(requested);
    fmt::print(stderr, "pathlab: --threads {} is more than {} x the {} cores: using {}\n", requested, kMaxThreadsPerCore, cores, cap);
    return cap;
}

}  // namespace pathlab
