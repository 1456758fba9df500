// --display-server HOST:PORT: the render as it converges, streamed to a running tev
// (display/tev_protocol.hpp). The render thread posts a frame (the film's current image and its
// extra channels) and goes on; a thread of the client's own connects, sends the newest frame
// posted and drops those it had no time for. A server that cannot be reached or goes away never
// stops or slows the render: the client says so once and tries again in the background, with
// the wait between attempts doubling up to kMaxRetrySeconds, and sends the newest frame again
// (CreateImage first) when it is back.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "image/image_io.hpp"

namespace pathlab {

// One picture for the viewer: width x height pixels of channels.size() interleaved floats.
struct DisplayFrame {
    std::string name;  // the image's name in tev ("cbox / pt-mis")
    int width = 0, height = 0;
    std::vector<std::string> channels;  // "R", "G", "B", then the extra layers ("albedo.R", ...)
    std::vector<float> pixels;
};

class Film;
// The film's current estimate (its mean: the splatting integrators' passes included, normalised
// by the passes so far) as channels R, G, B.
DisplayFrame film_frame(const std::string& name, const Film& film);
// Appends channels (each width x height values, e.g. the --aovs layers) to the frame, interleaved
// after its own, as extra layers in tev ("Albedo.R" goes in the layer Albedo).
void add_frame_channels(DisplayFrame& frame, const std::vector<ExrChannel>& channels);

struct DisplayAddress {
    std::string host;
    int port = 0;
};
// "HOST:PORT", "HOST" (tev's port 14158), "[IPv6]:PORT"; std::nullopt when malformed.
std::optional<DisplayAddress> parse_display_address(const std::string& text);

class DisplayServer {
public:
    struct Counters {
        uint64_t frames_sent = 0, packets = 0, bytes = 0;
        uint64_t connections = 0;  // successful connects
        uint64_t failures = 0;     // failed connects and lost connections
    };
    // `say` prints a message (from the client's thread): the first failure, and a connection
    // made after one. Connects at once, in the background.
    DisplayServer(DisplayAddress address, std::function<void(const std::string&)> say, double first_retry_seconds = 0.25);
    // Sends the last frame posted if a connection is up (waiting at most kFinalWaitSeconds), then closes.
    ~DisplayServer();
    DisplayServer(const DisplayServer&) = delete;
    DisplayServer& operator=(const DisplayServer&) = delete;

    // Replaces any frame not yet sent. Never waits for the network.
    void post(DisplayFrame frame);
    // Waits until every frame posted is sent or `seconds` pass; false when they do not.
    bool flush(double seconds);
    Counters counters() const;
    std::string address_text() const;

    static constexpr double kMaxRetrySeconds = 8;
    static constexpr double kFinalWaitSeconds = 5;

private:
    void run();
    bool connect_now(std::string& why);
    bool send_frame(const DisplayFrame& frame, std::string& why);
    bool send_all(std::span<const std::span<const char>> parts, std::string& why);
    void disconnect();

    DisplayAddress address_;
    std::function<void(const std::string&)> say_;
    double first_retry_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<DisplayFrame> pending_;
    bool sending_ = false, stop_ = false;
    bool attempted_ = false, connected_ = false;  // a connection was tried; one is up
    Counters counters_;
    // Thread-owned:
    int socket_ = -1;
    bool failed_before_ = false;
    std::map<std::string, std::pair<std::pair<int, int>, std::vector<std::string>>> created_;  // per name: size, channels
    std::thread thread_;
};

}  // namespace pathlab
