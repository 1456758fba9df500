// `pathlab_bench display` (part of `make bench`): what streaming to tev costs. Each algorithm
// renders the scene at size x size for `seconds`, without and with a display server (a viewer
// on 127.0.0.1 in this process that reads and checks every packet, as tev would), in
// interleaved pairs; the figures are medians over the pairs: samples per second of each, their
// ratio (the overhead), the frames the viewer received, and the time from the render's start
// (the scene already built) to the viewer holding the first complete image.
#include "display.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

#include <fmt/format.h>

#include "bench_common.hpp"
#include "display/display_server.hpp"
#include "job/render_job.hpp"
#include "job/scene_choice.hpp"

namespace pathlab::bench {
namespace {

using Clock = std::chrono::steady_clock;

// A viewer that reads every packet (lengths checked) and notes when the first image was complete.
class Viewer {
public:
    Viewer() {
        listener_ = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (::bind(listener_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 || ::listen(listener_, 1) != 0)
            throw std::runtime_error("viewer: cannot listen on loopback");
        socklen_t len = sizeof(a);
        getsockname(listener_, reinterpret_cast<sockaddr*>(&a), &len);
        port_ = ntohs(a.sin_port);
        thread_ = std::thread([this] { serve(); });
    }
    ~Viewer() {
        ::shutdown(listener_, SHUT_RDWR);
        ::close(listener_);
        thread_.join();
    }
    int port() const { return port_; }
    // Resets the figures for the next render.
    void reset() {
        updates_ = 0, first_image_ = Clock::time_point{};
    }
    uint64_t updates() const { return updates_; }
    Clock::time_point first_image() const { return first_image_; }

private:
    void serve() {
        while (true) {
            const int c = ::accept(listener_, nullptr, nullptr);
            if (c < 0) return;
            // Packets streamed through: each one's 5-byte header (length, type), then its rest skipped.
            char header[5];
            size_t in_header = 0, left = 0;
            char chunk[1 << 16];
            ssize_t n;
            while ((n = ::recv(c, chunk, sizeof(chunk), 0)) > 0) {
                for (size_t i = 0; i < size_t(n);) {
                    if (left == 0) {
                        header[in_header++] = chunk[i++];
                        if (in_header < 5) continue;
                        uint32_t length;
                        std::memcpy(&length, header, 4);
                        if (length < 5) throw std::runtime_error("viewer: a malformed packet");
                        left = length - 5, in_header = 0;
                        type_ = header[4];
                    } else {
                        const size_t take = std::min(left, size_t(n) - i);
                        i += take, left -= take;
                    }
                    if (left == 0 && in_header == 0 && type_ == 6) {
                        if (updates_ == 0) first_image_ = Clock::now();
                        ++updates_;
                        type_ = 0;
                    }
                }
            }
            ::close(c);
        }
    }
    int listener_ = -1, port_ = 0;
    char type_ = 0;
    std::atomic<uint64_t> updates_{0};
    std::atomic<Clock::time_point> first_image_{};
    std::thread thread_;
};

struct Run {
    double samples_per_second = 0, first_image_seconds = 0;
    uint64_t frames = 0;
};

Run render(const SceneChoice& choice, std::shared_ptr<const Scene> scene, const std::string& algorithm, const DisplayOptions& o,
           Viewer* viewer, uint64_t seed) {
    JobRequest r;
    r.algorithm = algorithm;
    r.width = r.height = o.size;
    r.time_limit = o.seconds;
    r.seed = seed;
    RenderJob job(choice, r, std::move(scene));
    std::unique_ptr<DisplayServer> server;
    if (viewer) {
        viewer->reset();
        server = std::make_unique<DisplayServer>(DisplayAddress{"127.0.0.1", viewer->port()},
                                                 [](const std::string& m) { fmt::print(stderr, "{}\n", m); });
        job.settings.display = [&](const Film& film, const RenderStats&) { server->post(film_frame("bench", film)); };
    }
    const Clock::time_point start = Clock::now();
    const RenderResult result = job.run();
    Run run;
    run.samples_per_second = double(result.stats.samples) / result.stats.seconds;
    if (viewer) {
        server.reset();  // the last frame sent
        run.frames = viewer->updates();
        run.first_image_seconds = std::chrono::duration<double>(viewer->first_image() - start).count();
    }
    return run;
}

}  // namespace

void display_suite(const DisplayOptions& o) {
    fmt::print("## Streaming to a viewer (--display-server)\n\n");
    fmt::print("Scene {}, {}x{} pixels, {} s per render, {} interleaved pairs without and with a viewer on loopback that reads "
               "every packet (medians; the image is sent after the first pass, then every 0.5 s, and at the end). First image: "
               "from the render's start (scene built) to the viewer holding the whole first image.\n\n",
               o.scene, o.size, o.size, o.seconds, o.repeats);
    fmt::print("| algorithm | Msamples/s without | Msamples/s with | with / without | frames received | first image (s) |\n");
    fmt::print("|---|---|---|---|---|---|\n");
    const SceneChoice choice = resolve_scenes(o.scene).at(0);
    std::shared_ptr<const Scene> scene = Scene::build(choice.description);
    Viewer viewer;
    for (const std::string& algorithm : o.algorithms) {
        std::vector<double> without, with, ratio, first, frames;
        for (int k = 0; k < o.repeats; ++k) {
            const Run a = render(choice, scene, algorithm, o, nullptr, uint64_t(k));
            const Run b = render(choice, scene, algorithm, o, &viewer, uint64_t(k));
            without.push_back(a.samples_per_second * 1e-6), with.push_back(b.samples_per_second * 1e-6);
            ratio.push_back(b.samples_per_second / a.samples_per_second);
            first.push_back(b.first_image_seconds), frames.push_back(double(b.frames));
        }
        fmt::print("| {} | {:.3f} | {:.3f} | {:.3f} | {:.0f} | {:.3f} |\n", algorithm, median(without), median(with), median(ratio),
                   median(frames), median(first));
    }
    fmt::print("\n");
}

}  // namespace pathlab::bench
