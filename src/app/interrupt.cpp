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
    // From now on either signal gets its default action: a second one ends the process.
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(SIGINT, &dfl, nullptr);
    sigaction(SIGTERM, &dfl, nullptr);
    int none = 0;
    g_signal.compare_exchange_strong(none, sig);
    g_interrupted.store(true);
    static const char int_msg[] = "\npathlab: interrupted; finishing the current pass and writing the image (Ctrl-C again to abort)\n";
    static const char term_msg[] = "\npathlab: terminated (SIGTERM); finishing the current pass and writing the image (a second signal aborts)\n";
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
    // While the handler runs, the other signal waits; it then finds the default action.
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sa.sa_flags = SA_RESETHAND;
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
