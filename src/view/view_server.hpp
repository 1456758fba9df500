// `pathlab view`'s HTTP server (cpp-httplib): the page (view_assets.hpp) and a small JSON and
// binary API over a ViewSession.
//   GET  /                    the page (index.html); /view.js, /view.css its script and style
//   GET  /api/state           JSON: the scene, the integrators (and why any cannot render it),
//                             each slot's algorithm, sampler, status, last image's number, spp,
//                             time and RMSE curve
//   GET  /api/frame/a, /b     the slot's last image: width x height x RGB float32, little-endian,
//                             top row first; headers X-Width, X-Height, X-Frame, X-Spp
//   GET  /api/reference       the reference image, the same way (404 without one)
//   POST /api/render          {"slot": "a"|"b", "algorithm": ..., "sampler": ...}: (re)starts a slot
//   POST /api/stop            {"slot": "b"}: stops a slot
// It serves nothing else: a path with a ".." segment, a backslash or an encoded slash or dot is
// refused (400) and any other path is 404. Bound to loopback, it also refuses requests whose
// Host is not the loopback address (a web page's DNS rebinding), and a POST that is not JSON
// (which another site's page could send without the browser asking first).
#pragma once

#include <memory>
#include <string>
#include <thread>

namespace httplib {
class Server;
}

namespace pathlab {

class ViewSession;

class ViewServer {
public:
    // Listens on `bind`:`port` (port 0: a free one) at once; std::runtime_error if it cannot.
    ViewServer(ViewSession& session, const std::string& bind, int port);
    ~ViewServer();  // stops serving
    ViewServer(const ViewServer&) = delete;
    ViewServer& operator=(const ViewServer&) = delete;

    int port() const { return port_; }
    std::string url() const;

private:
    ViewSession& session_;
    std::string bind_;
    int port_ = 0;
    std::unique_ptr<httplib::Server> server_;
    std::thread thread_;
};

// Whether a request target (as sent, before percent-decoding) or its decoded path tries to
// leave the page's files: a ".." segment, a backslash, a NUL, or an encoded '/', '\' or '.'.
bool view_path_refused(const std::string& target, const std::string& decoded_path);
// True for a bind address on the loopback interface (127.x.y.z, ::1, localhost).
bool is_loopback_address(const std::string& address);

}  // namespace pathlab
