#include "view/view_server.hpp"

#include <httplib.h>
#include <sys/socket.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "job/usage_error.hpp"
#include "view/view_assets.hpp"
#include "view/view_session.hpp"

namespace pathlab {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

std::string_view content_type(std::string_view path) {
    if (path.ends_with(".html")) return "text/html; charset=utf-8";
    if (path.ends_with(".js")) return "text/javascript; charset=utf-8";
    if (path.ends_with(".css")) return "text/css; charset=utf-8";
    if (path.ends_with(".svg")) return "image/svg+xml";
    return "application/octet-stream";
}

void send_json(httplib::Response& res, const nlohmann::json& j, int status = 200) {
    res.status = status;
    res.set_header("Cache-Control", "no-store");
    res.set_content(j.dump(), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message) { send_json(res, {{"error", message}}, status); }

void send_image(httplib::Response& res, const Image& image, uint64_t number, uint64_t spp) {
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Width", std::to_string(image.width()));
    res.set_header("X-Height", std::to_string(image.height()));
    res.set_header("X-Frame", std::to_string(number));
    res.set_header("X-Spp", std::to_string(spp));
    // Floats as they are in memory: little-endian on every machine pathlab builds for.
    static_assert(std::endian::native == std::endian::little);
    res.set_content(std::string(reinterpret_cast<const char*>(image.data()), 3 * sizeof(float) * image.pixel_count()),
                    "application/octet-stream");
}

// The name of a Host header's value, without the port ("[::1]:8080" -> "[::1]").
std::string host_name(const std::string& host) {
    if (host.starts_with("[")) return host.substr(0, host.find(']') + 1);
    return host.substr(0, host.find(':'));
}

int slot_index(const std::string& name) {
    if (name == "a") return 0;
    if (name == "b") return 1;
    throw UsageError(fmt::format("unknown slot '{}'; slots: a, b", name));
}

nlohmann::json slot_json(const ViewSlotState& s) {
    nlohmann::json j{{"active", s.active},   {"algorithm", s.algorithm}, {"sampler", s.sampler}, {"render", s.render},
                     {"status", s.status},   {"error", s.error},         {"output", s.output},   {"frame", 0},
                     {"spp", 0},             {"seconds", 0.0},           {"samples_per_second", 0.0}};
    if (s.frame) {
        j["frame"] = s.frame->number;
        j["spp"] = s.frame->spp;
        j["seconds"] = s.frame->seconds;
        j["samples_per_second"] = s.frame->seconds > 0 ? double(s.frame->samples) / s.frame->seconds : 0.0;
    }
    nlohmann::json curve = nlohmann::json::array();
    for (const auto& [t, e] : s.rmse) curve.push_back({t, e});
    j["rmse"] = std::move(curve);
    return j;
}

}  // namespace

bool view_path_refused(const std::string& target, const std::string& decoded_path) {
    const std::string raw = lower(target.substr(0, target.find('?')));
    if (raw.find("%2e") != std::string::npos || raw.find("%2f") != std::string::npos || raw.find("%5c") != std::string::npos ||
        raw.find("%00") != std::string::npos)
        return true;
    for (const std::string* p : {&target, &decoded_path}) {
        if (p->find('\\') != std::string::npos || p->find('\0') != std::string::npos) return true;
        // A ".." segment: "/..", "/../x", "x/.."
        for (size_t at = p->find(".."); at != std::string::npos; at = p->find("..", at + 1)) {
            const bool starts = at == 0 || (*p)[at - 1] == '/';
            const bool ends = at + 2 == p->size() || (*p)[at + 2] == '/' || (*p)[at + 2] == '?';
            if (starts && ends) return true;
        }
    }
    return false;
}

bool is_loopback_address(const std::string& address) {
    return address == "localhost" || address == "::1" || address == "[::1]" || address.starts_with("127.");
}

ViewServer::ViewServer(ViewSession& session, const std::string& bind, int port)
    : session_(session), bind_(bind), server_(std::make_unique<httplib::Server>()) {
    httplib::Server& srv = *server_;
    // SO_REUSEADDR alone: cpp-httplib's default adds SO_REUSEPORT, which lets a second pathlab
    // view listen on the same port and take half of the first one's requests.
    srv.set_socket_options([](int s) {  // (a socket_t, on Linux)
        int yes = 1;
        setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    });
    const bool loopback = is_loopback_address(bind);
    srv.set_pre_routing_handler([this, loopback](const httplib::Request& req, httplib::Response& res) {
        if (view_path_refused(req.target.empty() ? req.path : req.target, req.path)) {
            send_error(res, 400, "refused: the path leaves the viewer's files");
            return httplib::Server::HandlerResponse::Handled;
        }
        if (loopback) {
            // Host must name this server by a loopback name (a page elsewhere that rebinds its
            // own name to 127.0.0.1 sends its name).
            if (!is_loopback_address(host_name(req.get_header_value("Host")))) {
                send_error(res, 403, fmt::format("refused: Host '{}' is not this loopback server", req.get_header_value("Host")));
                return httplib::Server::HandlerResponse::Handled;
            }
        }
        if (req.method == "POST" && !req.get_header_value("Content-Type").starts_with("application/json")) {
            send_error(res, 415, "the API takes JSON (Content-Type: application/json)");
            return httplib::Server::HandlerResponse::Handled;
        }
        return httplib::Server::HandlerResponse::Unhandled;
    });

    srv.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
        const ViewSession& s = session_;
        nlohmann::json algorithms = nlohmann::json::array();
        for (const auto& [name, refusal] : s.algorithms()) algorithms.push_back({{"name", name}, {"refusal", refusal}});
        nlohmann::json slots = nlohmann::json::array();
        for (int i = 0; i < ViewSession::kSlots; ++i) slots.push_back(slot_json(s.slot(i)));
        send_json(res, {{"scene", s.scene().name},
                        {"width", s.width()},
                        {"height", s.height()},
                        {"algorithms", algorithms},
                        {"samplers", {"independent", "sobol"}},
                        {"reference", s.options().reference ? nlohmann::json(s.options().reference_name) : nlohmann::json()},
                        {"slots", slots}});
    });
    srv.Get(R"(/api/frame/(\w+))", [this](const httplib::Request& req, httplib::Response& res) {
        try {
            const ViewSlotState s = session_.slot(slot_index(req.matches[1]));
            if (!s.frame) return send_error(res, 404, "no image yet");
            send_image(res, s.frame->image, s.frame->number, s.frame->spp);
        } catch (const UsageError& e) {
            send_error(res, 404, e.what());
        }
    });
    srv.Get("/api/reference", [this](const httplib::Request&, httplib::Response& res) {
        if (!session_.options().reference) return send_error(res, 404, "no reference (pathlab view --reference FILE)");
        send_image(res, *session_.options().reference, 1, 0);
    });
    srv.Post("/api/render", [this](const httplib::Request& req, httplib::Response& res) {
        try {
            const nlohmann::json j = nlohmann::json::parse(req.body);
            const int slot = slot_index(j.value("slot", "a"));
            const ViewSlotState now = session_.slot(slot);
            session_.start(slot, j.value("algorithm", now.algorithm.empty() ? session_.slot(0).algorithm : now.algorithm),
                           j.value("sampler", now.sampler.empty() ? std::string("independent") : now.sampler));
            send_json(res, slot_json(session_.slot(slot)));
        } catch (const nlohmann::json::exception& e) {
            send_error(res, 400, fmt::format("malformed request: {}", e.what()));
        } catch (const std::exception& e) {
            send_error(res, 400, e.what());
        }
    });
    srv.Post("/api/stop", [this](const httplib::Request& req, httplib::Response& res) {
        try {
            const nlohmann::json j = nlohmann::json::parse(req.body);
            const int slot = slot_index(j.value("slot", "b"));
            session_.stop(slot);
            send_json(res, slot_json(session_.slot(slot)));
        } catch (const nlohmann::json::exception& e) {
            send_error(res, 400, fmt::format("malformed request: {}", e.what()));
        } catch (const std::exception& e) {
            send_error(res, 400, e.what());
        }
    });
    // The page's own files, and nothing else.
    srv.Get(".*", [](const httplib::Request& req, httplib::Response& res) {
        const std::string path = req.path == "/" ? "/index.html" : req.path;
        for (const ViewAsset& a : view_assets())
            if (a.path == path) {
                res.set_header("Cache-Control", "no-store");
                res.set_content(std::string(a.bytes), std::string(content_type(a.path)));
                return;
            }
        send_error(res, 404, fmt::format("no such file: {}", req.path));
    });

    port_ = port == 0 ? srv.bind_to_any_port(bind) : (srv.bind_to_port(bind, port) ? port : -1);
    if (port_ <= 0)
        throw std::runtime_error(port == 0 ? fmt::format("cannot listen on {}", bind) : fmt::format("cannot listen on {} port {} (in use?)", bind, port));
    thread_ = std::thread([this] { server_->listen_after_bind(); });
}

ViewServer::~ViewServer() {
    server_->stop();
    thread_.join();
}

std::string ViewServer::url() const {
    const std::string host = bind_.find(':') != std::string::npos ? "[" + bind_ + "]" : bind_;
    return fmt::format("http://{}:{}/", host == "0.0.0.0" ? "127.0.0.1" : host, port_);
}

}  // namespace pathlab
