#include "display/display_server.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include <fmt/format.h>

#include "display/tev_protocol.hpp"
#include "render/film.hpp"

namespace pathlab {

DisplayFrame film_frame(const std::string& name, const Film& film) {
    const Image mean = film.mean();  // the same floats as the image written
    return {name, film.width(), film.height(), {"R", "G", "B"}, std::vector<float>(mean.data(), mean.data() + 3 * mean.pixel_count())};
}

void add_frame_channels(DisplayFrame& frame, const std::vector<ExrChannel>& channels) {
    if (channels.empty()) return;
    const size_t pixels = size_t(frame.width) * size_t(frame.height), before = frame.channels.size(), after = before + channels.size();
    std::vector<float> out(pixels * after);
    for (size_t i = 0; i < pixels; ++i) {
        std::copy_n(frame.pixels.data() + i * before, before, out.data() + i * after);
        for (size_t c = 0; c < channels.size(); ++c) out[i * after + before + c] = channels[c].values.at(i);
    }
    for (const ExrChannel& c : channels) frame.channels.push_back(c.name);
    frame.pixels = std::move(out);
}

std::optional<DisplayAddress> parse_display_address(const std::string& text) {
    DisplayAddress a;
    std::string port;
    if (text.starts_with("[")) {
        const size_t close = text.find(']');
        if (close == std::string::npos) return std::nullopt;
        a.host = text.substr(1, close - 1);
        if (close + 1 < text.size()) {
            if (text[close + 1] != ':') return std::nullopt;
            port = text.substr(close + 2);
            if (port.empty()) return std::nullopt;
        }
    } else {
        const size_t colon = text.rfind(':');
        if (colon != std::string::npos && text.find(':') != colon) return std::nullopt;  // IPv6 without brackets
        a.host = text.substr(0, colon);
        if (colon != std::string::npos) {
            port = text.substr(colon + 1);
            if (port.empty()) return std::nullopt;
        }
    }
    if (a.host.empty()) return std::nullopt;
    a.port = tev::kDefaultPort;
    if (!port.empty()) {
        if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
        a.port = std::stoi(port);
        if (a.port < 1 || a.port > 65535) return std::nullopt;
    }
    return a;
}

DisplayServer::DisplayServer(DisplayAddress address, std::function<void(const std::string&)> say, double first_retry_seconds)
    : address_(std::move(address)), say_(std::move(say)), first_retry_(first_retry_seconds) {
    thread_ = std::thread([this] { run(); });
}

DisplayServer::~DisplayServer() {
    {
        std::unique_lock lock(mutex_);
        // The last frame goes out if a connection is up; an unreachable server is not waited for.
        // The first attempt to connect is waited for (it takes at most a second), so that a
        // short render still reaches a viewer that is there.
        const auto limit = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                  std::chrono::duration<double>(kFinalWaitSeconds));
        wake_.wait_until(lock, limit, [&] { return attempted_; });
        if (connected_) wake_.wait_until(lock, limit, [&] { return !connected_ || (!pending_ && !sending_); });
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
    disconnect();
}

std::string DisplayServer::address_text() const {
    return address_.host.find(':') != std::string::npos ? fmt::format("[{}]:{}", address_.host, address_.port)
                                                        : fmt::format("{}:{}", address_.host, address_.port);
}

void DisplayServer::post(DisplayFrame frame) {
    {
        std::lock_guard lock(mutex_);
        pending_ = std::move(frame);
    }
    wake_.notify_all();
}

bool DisplayServer::flush(double seconds) {
    std::unique_lock lock(mutex_);
    return wake_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return !pending_ && !sending_; });
}

DisplayServer::Counters DisplayServer::counters() const {
    std::lock_guard lock(mutex_);
    return counters_;
}

void DisplayServer::disconnect() {
    if (socket_ >= 0) ::close(socket_);
    socket_ = -1;
    created_.clear();
}

bool DisplayServer::connect_now(std::string& why) {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    if (const int e = getaddrinfo(address_.host.c_str(), std::to_string(address_.port).c_str(), &hints, &found); e != 0) {
        why = fmt::format("cannot resolve {}: {}", address_.host, gai_strerror(e));
        return false;
    }
    why = "no address";
    for (addrinfo* a = found; a; a = a->ai_next) {
        const int s = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
        if (s < 0) {
            why = std::strerror(errno);
            continue;
        }
        // Connect without blocking for longer than a second, then send with a time limit.
        fcntl(s, F_SETFL, fcntl(s, F_GETFL, 0) | O_NONBLOCK);
        int r = ::connect(s, a->ai_addr, a->ai_addrlen);
        if (r < 0 && errno == EINPROGRESS) {
            pollfd p{s, POLLOUT, 0};
            r = ::poll(&p, 1, 1000);
            int error = r == 0 ? ETIMEDOUT : 0;
            socklen_t len = sizeof(error);
            if (r > 0) getsockopt(s, SOL_SOCKET, SO_ERROR, &error, &len);
            if (r < 0) error = errno;
            r = error ? -1 : 0;
            errno = error;
        }
        if (r < 0) {
            why = std::strerror(errno);
            ::close(s);
            continue;
        }
        fcntl(s, F_SETFL, fcntl(s, F_GETFL, 0) & ~O_NONBLOCK);
        timeval limit{5, 0};
        setsockopt(s, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof(limit));
        const int one = 1;
        setsockopt(s, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
        socket_ = s;
        freeaddrinfo(found);
        return true;
    }
    freeaddrinfo(found);
    return false;
}

bool DisplayServer::send_all(std::span<const std::span<const char>> parts, std::string& why) {
    size_t total = 0;
    for (const auto& p : parts) total += p.size();
    for (const auto& part : parts) {
        size_t sent = 0;
        while (sent < part.size()) {
            // MSG_NOSIGNAL: a closed connection is an error here, not a SIGPIPE that ends pathlab.
            const ssize_t n = ::send(socket_, part.data() + sent, part.size() - sent, MSG_NOSIGNAL);
            if (n < 0) {
                if (errno == EINTR) continue;
                why = errno == EAGAIN || errno == EWOULDBLOCK ? "the viewer took no data for 5 s" : std::strerror(errno);
                return false;
            }
            sent += size_t(n);
        }
    }
    std::lock_guard lock(mutex_);
    ++counters_.packets, counters_.bytes += total;
    return true;
}

bool DisplayServer::send_frame(const DisplayFrame& f, std::string& why) {
    const auto shape = std::make_pair(std::make_pair(f.width, f.height), f.channels);
    auto it = created_.find(f.name);
    if (it == created_.end() || it->second != shape) {
        const std::vector<char> create = tev::create_image(f.name, f.width, f.height, f.channels);
        const std::span<const char> parts[] = {create};
        if (!send_all(parts, why)) return false;
        created_[f.name] = shape;
    }
    // Row stripes, each a header and then the frame's own rows (not copied).
    const int n = int(f.channels.size()), rows = tev::stripe_rows(f.width, n);
    const size_t pitch = size_t(f.width) * size_t(n);
    for (int y = 0; y < f.height; y += rows) {
        const int h = std::min(rows, f.height - y);
        const std::vector<char> header = tev::update_image_header(f.name, f.channels, 0, y, f.width, h);
        const std::span<const char> parts[] = {
            header, {reinterpret_cast<const char*>(f.pixels.data() + size_t(y) * pitch), size_t(h) * pitch * sizeof(float)}};
        if (!send_all(parts, why)) return false;
    }
    return true;
}

void DisplayServer::run() {
    using clock = std::chrono::steady_clock;
    double retry = first_retry_;
    clock::time_point next_attempt = clock::now();
    std::unique_lock lock(mutex_);
    while (!stop_) {
        if (socket_ < 0) {
            // Wait for the next attempt (or the end).
            if (wake_.wait_until(lock, next_attempt, [&] { return stop_; })) break;
            lock.unlock();
            std::string why;
            const bool up = connect_now(why);
            lock.lock();
            attempted_ = true;
            if (!up) {
                wake_.notify_all();
                ++counters_.failures;
                if (!failed_before_)
                    say_(fmt::format("display server {}: cannot connect ({}); the render goes on, and pathlab tries again in the "
                                     "background",
                                     address_text(), why));
                failed_before_ = true;
                next_attempt = clock::now() + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(retry));
                retry = std::min(2 * retry, kMaxRetrySeconds);
                continue;
            }
            ++counters_.connections;
            connected_ = true;
            if (failed_before_) say_(fmt::format("display server {}: connected", address_text()));
            retry = first_retry_;
            wake_.notify_all();
        }
        wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
        if (stop_) break;
        DisplayFrame frame = std::move(*pending_);
        pending_.reset();
        sending_ = true;
        lock.unlock();
        std::string why;
        const bool ok = send_frame(frame, why);
        lock.lock();
        sending_ = false;
        if (ok) {
            ++counters_.frames_sent;
        } else {
            ++counters_.failures;
            if (!pending_) pending_ = std::move(frame);  // sent again when the connection is back
            connected_ = false;
            lock.unlock();
            disconnect();
            lock.lock();
            if (!failed_before_)
                say_(fmt::format("display server {}: connection lost ({}); the render goes on, and pathlab tries again in the background",
                                 address_text(), why));
            failed_before_ = true;
            next_attempt = clock::now() + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(retry));
            retry = std::min(2 * retry, kMaxRetrySeconds);
        }
        wake_.notify_all();
    }
}

}  // namespace pathlab
