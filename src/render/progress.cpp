#include "render/progress.hpp"

#include <cstdio>

#include <fmt/format.h>

namespace pathlab {

namespace {
std::string format_seconds(double s) {
    if (s < 60) return fmt::format("{:.1f}s", s);
    if (s < 3600) return fmt::format("{}m{:02}s", int(s) / 60, int(s) % 60);
    return fmt::format("{}h{:02}m", int(s) / 3600, (int(s) / 60) % 60);
}
}  // namespace

Progress::Progress(bool enabled, std::string label)
    : enabled_(enabled), label_(std::move(label)), start_(std::chrono::steady_clock::now()) {}

double Progress::elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::update(double fraction, uint64_t samples, const std::string& detail) {
    if (!enabled_) return;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_draw_ < std::chrono::milliseconds(200) && fraction < 1) return;
    last_draw_ = now;
    const double t = elapsed();
    const std::string eta = fraction > 0.001 ? format_seconds(t * (1 - fraction) / fraction) : "?";
    std::string line = fmt::format("{}{:5.1f}% | {} elapsed | ETA {} | {:.2f} Msamples/s", label_, 100 * fraction,
                                   format_seconds(t), eta, t > 0 ? double(samples) / t * 1e-6 : 0.0);
    if (!detail.empty()) line += " | " + detail;
    const size_t width = line.size();
    if (width < last_width_) line.append(last_width_ - width, ' ');
    last_width_ = width;
    fmt::print(stderr, "\r{}", line);
    std::fflush(stderr);
}

void Progress::finish() {
    if (!enabled_ || last_width_ == 0) return;
    std::lock_guard lock(mutex_);
    fmt::print(stderr, "\r{}\r", std::string(last_width_, ' '));
    std::fflush(stderr);
    last_width_ = 0;
}

}  // namespace pathlab
