// Ctrl-C and SIGTERM handling for long renders: the first SIGINT or SIGTERM asks the render to
// stop after its current pass (the image so far is then written, normalised by the samples
// taken); a second one of either prints that it aborted and exits at once (128 + the signal)
// without writing an image.
//
// The exit code of an interrupted command is 128 + the signal, as shells report a process
// killed by it: 130 after Ctrl-C (SIGINT), 143 after SIGTERM (what job schedulers and `kill`
// send). Commands return interrupted_exit_code() when they stop because of the flag.
#pragma once

#include <atomic>

namespace pathlab {

class InterruptGuard {
public:
    InterruptGuard();   // installs the SIGINT and SIGTERM handlers, clears the flag
    ~InterruptGuard();  // restores the previous handlers
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;
    static const std::atomic<bool>& flag();
};

// The signal that set the flag (SIGINT or SIGTERM), 0 if none has since the last guard was made.
int interrupting_signal();

// The exit code for a command stopped by the flag: 128 + the signal (130 for SIGINT, 143 for
// SIGTERM); 130 when no signal was recorded.
int interrupted_exit_code();

}  // namespace pathlab
