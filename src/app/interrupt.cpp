#include "app/interrupt.hpp"

#include <unistd.h>

#include <csignal>

namespace pathlab {
namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the flag is written from a signal handler");
struct sigaction g_previous {};

extern "C" void on_sigint(int) {
    g_interrupted.store(true);
    static const char msg[] = "\npathlab: interrupted; finishing the current pass and writing the image (Ctrl-C again to abort)\n";
    [[maybe_unused]] const ssize_t n = write(STDERR_FILENO, msg, sizeof(msg) - 1);
}

}  // namespace

InterruptGuard::InterruptGuard() {
    g_interrupted = false;
    struct sigaction sa {};
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;  // a second Ctrl-C gets the default action: the process ends
    sigaction(SIGINT, &sa, &g_previous);
}

InterruptGuard::~InterruptGuard() { sigaction(SIGINT, &g_previous, nullptr); }

const std::atomic<bool>& InterruptGuard::flag() { return g_interrupted; }

}  // namespace pathlab
