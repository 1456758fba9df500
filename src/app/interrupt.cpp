#include "app/interrupt.hpp"

#include <unistd.h>

#include <csignal>

namespace pathlab {
namespace {

std::atomic<bool> g_interrupted{false};
std::atomic<int> g_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "the flag and the signal are written from a signal handler");
struct sigaction g_previous_int {}, g_previous_term {};

extern "C" void on_stop_signal(int sig) {
    if (g_interrupted.load()) {
        // The second signal: abort at once, writing nothing (outputs are written through
        // temporaries, so no half-written image is left under an output's name).
        static const char abort_msg[] = "\npathlab: aborted; no image written\n";
        [[maybe_unused]] const ssize_t n = write(STDERR_FILENO, abort_msg, sizeof(abort_msg) - 1);
        _exit(128 + (sig == SIGTERM ? SIGTERM : SIGINT));
    }
    int none = 0;
    g_signal.compare_exchange_strong(none, sig);
    g_interrupted.store(true);
    static const char int_msg[] = "\npathlab: interrupted; finishing the current pass and writing the image (Ctrl-C again to abort without it)\n";
    static const char term_msg[] = "\npathlab: terminated (SIGTERM); finishing the current pass and writing the image (a second signal aborts without it)\n";
    const bool term = sig == SIGTERM;
    [[maybe_unused]] const ssize_t n =
        write(STDERR_FILENO, term ? term_msg : int_msg, (term ? sizeof(term_msg) : sizeof(int_msg)) - 1);
}

}  // namespace

InterruptGuard::InterruptGuard() {
    g_interrupted = false;
    g_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    // While the handler runs, the other signal waits; it then finds the flag set and aborts.
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sa.sa_flags = 0;
    sigaction(SIGINT, &sa, &g_previous_int);
    sigaction(SIGTERM, &sa, &g_previous_term);
}

InterruptGuard::~InterruptGuard() {
    sigaction(SIGINT, &g_previous_int, nullptr);
    sigaction(SIGTERM, &g_previous_term, nullptr);
}

const std::atomic<bool>& InterruptGuard::flag() { return g_interrupted; }

int interrupting_signal() { return g_signal.load(); }

int interrupted_exit_code() {
    const int sig = g_signal.load();
    return 128 + (sig == SIGTERM ? SIGTERM : SIGINT);
}

}  // namespace pathlab
