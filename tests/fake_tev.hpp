// A fake tev for the tests: a server on 127.0.0.1 that keeps what each connection sent, and a
// reader of tev's IPC packets written from tev's own reader (src/Ipc.cpp), independently of
// pathlab's writer (display/tev_protocol.cpp).
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace pathlab::test {

// A packet as tev reads it.
struct TevPacket {
    int type = -1;
    bool grab_focus = false;
    std::string name;
    int width = 0, height = 0, x = 0, y = 0;
    std::vector<std::string> channels;
    std::vector<std::vector<float>> data;  // per channel, the region's pixels
};

class TevPacketReader {
public:
    TevPacketReader(const char* p, size_t n) : p_(p), n_(n) {}
    template <class T>
    T get() {
        if (i_ + sizeof(T) > n_) throw std::runtime_error("packet too short");
        T v;
        std::memcpy(&v, p_ + i_, sizeof(T));
        i_ += sizeof(T);
        return v;
    }
    std::string str() {
        std::string s;
        while (true) {
            if (i_ >= n_) throw std::runtime_error("string past the packet's end");
            if (p_[i_] == '\0') break;
            s += p_[i_++];
        }
        ++i_;
        return s;
    }
    size_t left() const { return n_ - i_; }
    const char* here() const { return p_ + i_; }

private:
    const char* p_;
    size_t n_, i_ = 0;
};

inline std::vector<TevPacket> parse_packets(const std::string& bytes) {
    std::vector<TevPacket> out;
    size_t at = 0;
    while (at < bytes.size()) {
        if (bytes.size() - at < 5) throw std::runtime_error("a partial packet header");
        uint32_t length;
        std::memcpy(&length, bytes.data() + at, 4);
        if (length < 5 || at + length > bytes.size()) throw std::runtime_error("a packet's length past the stream");
        TevPacketReader r(bytes.data() + at + 4, length - 4);
        TevPacket p;
        p.type = r.get<uint8_t>();
        if (p.type == 2) {
            p.name = r.str();
        } else if (p.type == 4) {
            p.grab_focus = r.get<uint8_t>() == 1;
            p.name = r.str();
            p.width = r.get<int32_t>(), p.height = r.get<int32_t>();
            const int n = r.get<int32_t>();
            for (int c = 0; c < n; ++c) p.channels.push_back(r.str());
        } else if (p.type == 6) {
            p.grab_focus = r.get<uint8_t>() == 1;
            p.name = r.str();
            const int n = r.get<int32_t>();
            for (int c = 0; c < n; ++c) p.channels.push_back(r.str());
            p.x = r.get<int32_t>(), p.y = r.get<int32_t>(), p.width = r.get<int32_t>(), p.height = r.get<int32_t>();
            std::vector<int64_t> offset(static_cast<size_t>(n)), stride(static_cast<size_t>(n));
            for (auto& o : offset) o = r.get<int64_t>();
            for (auto& s : stride) s = r.get<int64_t>();
            const size_t pixels = size_t(p.width) * size_t(p.height);
            size_t needed = 0;
            for (int c = 0; c < n; ++c) needed = std::max(needed, size_t(offset[size_t(c)] + int64_t(pixels - 1) * stride[size_t(c)] + 1));
            if (r.left() != needed * sizeof(float)) throw std::runtime_error("UpdateImage: data of another size than its header says");
            const float* f = reinterpret_cast<const float*>(r.here());
            p.data.assign(size_t(n), std::vector<float>(pixels));
            for (int c = 0; c < n; ++c)
                for (size_t i = 0; i < pixels; ++i) std::memcpy(&p.data[size_t(c)][i], f + offset[size_t(c)] + int64_t(i) * stride[size_t(c)], 4);
        } else {
            throw std::runtime_error("unknown packet type " + std::to_string(p.type));
        }
        out.push_back(std::move(p));
        at += length;
    }
    return out;
}

// A tev on 127.0.0.1 (a free port): accepts connections one after another and keeps what each
// sent; with close_at_once it closes every connection as soon as it is made.
class FakeTev {
public:
    explicit FakeTev(bool close_at_once = false, int port = 0) : close_at_once_(close_at_once) {
        listener_ = ::socket(AF_INET, SOCK_STREAM, 0);
        const int one = 1;
        setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        a.sin_port = htons(uint16_t(port));
        if (::bind(listener_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 || ::listen(listener_, 4) != 0)
            throw std::runtime_error("fake tev: cannot listen");
        socklen_t len = sizeof(a);
        getsockname(listener_, reinterpret_cast<sockaddr*>(&a), &len);
        port_ = ntohs(a.sin_port);
        thread_ = std::thread([this] { serve(); });
    }
    ~FakeTev() {
        ::shutdown(listener_, SHUT_RDWR);
        ::close(listener_);
        thread_.join();
    }
    int port() const { return port_; }
    std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
    // What each connection sent, once it closed.
    std::vector<std::string> connections() {
        std::lock_guard lock(mutex_);
        return done_;
    }
    int accepted() {
        std::lock_guard lock(mutex_);
        return accepted_;
    }

private:
    void serve() {
        while (true) {
            const int c = ::accept(listener_, nullptr, nullptr);
            if (c < 0) return;
            {
                std::lock_guard lock(mutex_);
                ++accepted_;
            }
            std::string bytes;
            if (!close_at_once_) {
                char buf[1 << 16];
                ssize_t n;
                while ((n = ::recv(c, buf, sizeof(buf), 0)) > 0) bytes.append(buf, size_t(n));
            }
            ::close(c);
            std::lock_guard lock(mutex_);
            done_.push_back(std::move(bytes));
        }
    }
    bool close_at_once_;
    int listener_ = -1, port_ = 0;
    std::mutex mutex_;
    int accepted_ = 0;
    std::vector<std::string> done_;
    std::thread thread_;
};

// Waits (up to 10 s) for the fake tev to have seen `n` connections end.
inline std::vector<std::string> wait_for(FakeTev& tev, size_t n) {
    for (int i = 0; i < 1000 && tev.connections().size() < n; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return tev.connections();
}

}  // namespace pathlab::test
