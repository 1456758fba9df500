// `pathlab_bench display` (part of `make bench`): what streaming to tev and `pathlab view` cost.
// Each algorithm renders the scene at size x size for `seconds`, without and with a display
// server (a viewer on 127.0.0.1 in this process that reads and checks every packet, as tev
// would), and in `pathlab view` with a client polling as its page does, in interleaved triples;
// the figures are medians over them: samples per second of each, their
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
#include <httplib.h>
#include <nlohmann/json.hpp>

#include "display/display_server.hpp"
#include "job/render_job.hpp"
#include "job/scene_choice.hpp"
#include "view/view_server.hpp"
#include "view/view_session.hpp"

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

// The same render in `pathlab view` with the page open: a client that does what the page does
// (state every 200 ms, the image whenever there is a new one) over HTTP on loopback.
Run render_in_view(const SceneChoice& choice, const std::string& algorithm, const DisplayOptions& o, uint64_t seed) {
    ViewSession::Options v;
    v.scene = choice;
    v.request.algorithm = algorithm;
    v.request.width = v.request.height = o.size;
    v.request.time_limit = o.seconds;
    v.request.seed = seed;
    ViewSession session(std::move(v));  // the scene built, the render started
    const Clock::time_point start = Clock::now();
    ViewServer server(session, "127.0.0.1", 0);
    std::atomic<bool> stop{false};
    Run run;
    std::thread page([&] {
        httplib::Client c("127.0.0.1", server.port());
        uint64_t have = 0;
        while (!stop) {
            if (auto st = c.Get("/api/state")) {
                const uint64_t now = nlohmann::json::parse(st->body)["slots"][0]["frame"];
                if (now != have) {
                    auto img = c.Get("/api/frame/a");
                    if (img && img->status == 200) {
                        if (run.frames++ == 0) run.first_image_seconds = std::chrono::duration<double>(Clock::now() - start).count();
                        have = std::stoull(img->get_header_value("X-Frame"));
                    }
                }
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
        }
    });
    session.wait(0, o.seconds + 600);
    stop = true;
    page.join();
    const ViewSlotState a = session.slot(0);
    run.samples_per_second = a.frame && a.frame->seconds > 0 ? double(a.frame->samples) / a.frame->seconds : 0;
    return run;
}

}  // namespace

void display_suite(const DisplayOptions& o) {
    fmt::print("## Streaming to a viewer (--display-server)\n\n");
    fmt::print("Scene {}, {}x{} pixels, {} s per render, {} interleaved triples: without a viewer, with a viewer on loopback "
               "that reads every packet (the image is sent after the first pass, then every 0.5 s, and at the end), and in "
               "pathlab view with a client that polls as its page does (state every 200 ms, each new image; the view publishes "
               "every 0.25 s); medians. First image: from the render's start (scene built) to the viewer holding the whole first image.\n\n",
               o.scene, o.size, o.size, o.seconds, o.repeats);
    fmt::print("| algorithm | Msamples/s without | Msamples/s with | with / without | frames received | first image (s) | "
               "Msamples/s in pathlab view, page open | view / without | view frames fetched | view first image (s) |\n");
    fmt::print("|---|---|---|---|---|---|---|---|---|---|\n");
    const SceneChoice choice = resolve_scenes(o.scene).at(0);
    std::shared_ptr<const Scene> scene = Scene::build(choice.description);
    Viewer viewer;
    for (const std::string& algorithm : o.algorithms) {
        std::vector<double> without, with, ratio, first, frames, in_view, view_ratio, view_frames, view_first;
        for (int k = 0; k < o.repeats; ++k) {
            const Run a = render(choice, scene, algorithm, o, nullptr, uint64_t(k));
            const Run b = render(choice, scene, algorithm, o, &viewer, uint64_t(k));
            const Run c = render_in_view(choice, algorithm, o, uint64_t(k));
            without.push_back(a.samples_per_second * 1e-6), with.push_back(b.samples_per_second * 1e-6);
            ratio.push_back(b.samples_per_second / a.samples_per_second);
            first.push_back(b.first_image_seconds), frames.push_back(double(b.frames));
            in_view.push_back(c.samples_per_second * 1e-6), view_ratio.push_back(c.samples_per_second / a.samples_per_second);
            view_frames.push_back(double(c.frames)), view_first.push_back(c.first_image_seconds);
        }
        fmt::print("| {} | {:.3f} | {:.3f} | {:.3f} | {:.0f} | {:.3f} | {:.3f} | {:.3f} | {:.0f} | {:.3f} |\n", algorithm, median(without),
                   median(with), median(ratio), median(frames), median(first), median(in_view), median(view_ratio), median(view_frames),
                   median(view_first));
    }
    fmt::print("\n");
}

}  // namespace pathlab::bench
