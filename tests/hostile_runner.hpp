// Runs a piece of code on hostile input in a child process with a time limit and a memory
// limit, so that a reader that hangs, crashes or allocates without bound fails a test instead
// of hanging or killing the test binary. For tests/test_hostile_inputs.cpp.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>

#include "geometry/shape_meshes.hpp"
#include "image/image_io.hpp"
#include "media/grid_files.hpp"

namespace pathlab::test {

enum class Outcome { Loaded, CleanError, OtherException, Crashed, TimedOut };

inline const char* outcome_name(Outcome o) {
    switch (o) {
        case Outcome::Loaded: return "loaded";
        case Outcome::CleanError: return "clean error";
        case Outcome::OtherException: return "other exception";
        case Outcome::Crashed: return "crashed";
        case Outcome::TimedOut: return "timed out";
    }
    return "?";
}

struct BoundedResult {
    Outcome outcome;
    std::string message;  // the error's what(), or what went wrong
    double seconds;
};

// Virtual memory of this process now, in bytes.
inline size_t current_address_space() {
    std::ifstream statm("/proc/self/statm");
    size_t pages = 0;
    statm >> pages;
    return pages * size_t(sysconf(_SC_PAGESIZE));
}

// Runs fn() in a child process that may take `seconds` and allocate `extra_bytes` more address
// space than this process has. fn returning is Loaded, an ImageIoError, MeshLoadError or GridFileError
// is a CleanError, any other exception (std::bad_alloc when the memory limit is hit) is an
// OtherException, a signal is Crashed, running out of time is TimedOut (the child is killed).
inline BoundedResult run_bounded(const std::function<void()>& fn, double seconds = 10, size_t extra_bytes = size_t(512) << 20) {
    int pipe_fds[2];
    if (pipe(pipe_fds) != 0) throw std::runtime_error("pipe failed");
    const size_t limit = current_address_space() + extra_bytes;
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
        close(pipe_fds[0]);
        const rlimit rl{limit, limit};
        setrlimit(RLIMIT_AS, &rl);
        char kind = 'O';
        std::string message;
        try {
            fn();
        } catch (const ImageIoError& e) {
            kind = 'E', message = e.what();
        } catch (const MeshLoadError& e) {
            kind = 'E', message = e.what();
        } catch (const GridFileError& e) {
            kind = 'E', message = e.what();
        } catch (const std::exception& e) {
            kind = 'X', message = e.what();
        } catch (...) {
            kind = 'X', message = "an exception that is not a std::exception";
        }
        const std::string out = kind + message;
        [[maybe_unused]] ssize_t n = write(pipe_fds[1], out.data(), out.size());
        _exit(0);
    }
    close(pipe_fds[1]);
    std::string received;
    bool timed_out = false;
    for (;;) {
        const double left = seconds - std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (left <= 0) {
            timed_out = true;
            break;
        }
        pollfd p{pipe_fds[0], POLLIN, 0};
        if (poll(&p, 1, int(left * 1000) + 1) <= 0) continue;
        char buf[4096];
        const ssize_t n = read(pipe_fds[0], buf, sizeof buf);
        if (n <= 0) break;  // the child closed its end: it is done
        received.append(buf, size_t(n));
    }
    close(pipe_fds[0]);
    if (timed_out) kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (timed_out) return {Outcome::TimedOut, "no result within the time limit", took};
    if (WIFSIGNALED(status)) return {Outcome::Crashed, std::string("killed by signal ") + strsignal(WTERMSIG(status)), took};
    if (received.empty()) return {Outcome::Crashed, "the child exited without a result", took};
    const Outcome o = received[0] == 'O' ? Outcome::Loaded : received[0] == 'E' ? Outcome::CleanError : Outcome::OtherException;
    return {o, received.substr(1), took};
}

}  // namespace pathlab::test
