// Ctrl-C handling for long renders: the first SIGINT asks the render to stop after its
// current pass (the image so far is then written); a second one kills the process.
#pragma once

#include <atomic>

namespace pathlab {

class InterruptGuard {
public:
    InterruptGuard();   // installs the SIGINT handler
    ~InterruptGuard();  // restores the previous handler
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;
    static const std::atomic<bool>& flag();
};

}  // namespace pathlab
