// A one-line progress report on stderr (percent, elapsed, ETA, throughput), redrawn in place.
// Silent when disabled (e.g. stderr is not a terminal).
#pragma once

#include <chrono>
#include <mutex>
#include <string>

namespace pathlab {

class Progress {
public:
    explicit Progress(bool enabled, std::string label = {});
    // fraction in [0,1]; samples = total samples so far. Thread-safe; rate-limited to ~5 Hz.
    void update(double fraction, uint64_t samples, const std::string& detail = {});
    // Clears the line.
    void finish();
    double elapsed() const;

private:
    bool enabled_;
    std::string label_;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_draw_{};
    std::mutex mutex_;
    size_t last_width_ = 0;
};

}  // namespace pathlab
