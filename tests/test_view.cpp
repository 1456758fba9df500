// `pathlab view`'s server side: the images a slot publishes are the film's (the last one equal,
// byte for byte, to the same render made by RenderJob), a restart renders with the new
// integrator, the RMSE curve is the RMSE of the images against the reference, and the HTTP API
// serves the page's files, the images and the state, and refuses paths that leave them, other
// Hosts and POSTs that are not JSON. (The page itself is tested in Chromium: tests/view_test.py.)
#include <gtest/gtest.h>

#include <httplib.h>

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "job/usage_error.hpp"
#include "view/view_server.hpp"
#include "view/view_session.hpp"

namespace pathlab::test {
namespace {

ViewSession::Options small_view(uint64_t spp, const std::string& algorithm = "pt-mis") {
    ViewSession::Options o;
    o.scene = builtin_scene_choice(3);
    o.request.algorithm = algorithm;
    o.request.width = 16, o.request.height = 12;
    o.request.spp = spp;
    o.request.seed = 7;
    o.publish_every = 0;  // every round
    return o;
}

Image render_alone(const std::string& algorithm, uint64_t spp) {
    const ViewSession::Options o = small_view(spp, algorithm);
    JobRequest r = o.request;
    RenderJob job(o.scene, r);
    return job.run().film.mean();
}

bool same_bytes(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.data(), b.data(), 3 * sizeof(float) * a.pixel_count()) == 0;
}

TEST(ViewSession, LastImageIsTheRendersFilm) {
    ViewSession s(small_view(8));
    ASSERT_TRUE(s.wait(0, 60));
    const ViewSlotState a = s.slot(0);
    EXPECT_EQ(a.status, "done");
    EXPECT_EQ(a.algorithm, "pt-mis");
    ASSERT_TRUE(a.frame);
    EXPECT_EQ(a.frame->spp, 8u);
    EXPECT_TRUE(same_bytes(a.frame->image, render_alone("pt-mis", 8)));
}

TEST(ViewSession, RestartRendersWithTheNewIntegratorAndBadNamesLeaveItAlone) {
    ViewSession s(small_view(4));
    ASSERT_TRUE(s.wait(0, 60));
    s.start(0, "lt", "independent");
    ASSERT_TRUE(s.wait(0, 60));
    const ViewSlotState a = s.slot(0);
    EXPECT_EQ(a.algorithm, "lt");
    EXPECT_EQ(a.render, 2u);
    ASSERT_TRUE(a.frame);
    EXPECT_TRUE(same_bytes(a.frame->image, render_alone("lt", 4)));
    EXPECT_THROW(s.start(0, "no-such-estimator", "independent"), UsageError);
    EXPECT_THROW(s.start(0, "pt-mis", "halton"), UsageError);
    EXPECT_EQ(s.slot(0).render, 2u);
}

TEST(ViewSession, RmseCurveIsAgainstTheReference) {
    ViewSession::Options o = small_view(4);
    Image reference = render_alone("pt-mis", 64);
    o.reference = reference;
    ViewSession s(std::move(o));
    ASSERT_TRUE(s.wait(0, 60));
    const ViewSlotState a = s.slot(0);
    ASSERT_FALSE(a.rmse.empty());
    double sum = 0;
    for (size_t i = 0; i < 3 * reference.pixel_count(); ++i) {
        const double d = double(a.frame->image.data()[i]) - double(reference.data()[i]);
        sum += d * d;
    }
    EXPECT_DOUBLE_EQ(a.rmse.back().second, std::sqrt(sum / double(3 * reference.pixel_count())));
    EXPECT_GT(a.rmse.back().second, 0.0);
}

TEST(ViewSession, ReferenceOfAnotherSizeIsRefused) {
    ViewSession::Options o = small_view(1);
    o.reference = Image(5, 5);
    o.reference_name = "ref.exr";
    EXPECT_THROW(ViewSession(std::move(o)), UsageError);
}

TEST(ViewPaths, LeavingThePagesFilesIsRefused) {
    EXPECT_FALSE(view_path_refused("/", "/"));
    EXPECT_FALSE(view_path_refused("/view.js", "/view.js"));
    EXPECT_FALSE(view_path_refused("/api/frame/a?x=1", "/api/frame/a"));
    EXPECT_FALSE(view_path_refused("/a..b", "/a..b"));  // not a segment
    EXPECT_TRUE(view_path_refused("/../etc/passwd", "/../etc/passwd"));
    EXPECT_TRUE(view_path_refused("/view.js/..", "/view.js/.."));
    EXPECT_TRUE(view_path_refused("/%2e%2e/etc/passwd", "/../etc/passwd"));
    EXPECT_TRUE(view_path_refused("/%2E%2E%2Fetc", "/../etc"));
    EXPECT_TRUE(view_path_refused("/..%5cetc", "/..\\etc"));
    EXPECT_TRUE(view_path_refused("/a\\b", "/a\\b"));
    EXPECT_TRUE(view_path_refused("/view%2ejs", "/view.js"));  // an encoded dot, even where it is harmless
    EXPECT_TRUE(view_path_refused("/x%00.html", std::string("/x\0.html", 8)));
}

TEST(ViewServer, ServesThePageTheImagesAndTheState) {
    ViewSession s(small_view(4));
    ASSERT_TRUE(s.wait(0, 60));
    ViewServer server(s, "127.0.0.1", 0);
    httplib::Client c("127.0.0.1", server.port());

    auto page = c.Get("/");
    ASSERT_TRUE(page);
    EXPECT_EQ(page->status, 200);
    EXPECT_NE(page->body.find("<canvas id=\"image\""), std::string::npos);
    EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
    auto script = c.Get("/view.js");
    ASSERT_TRUE(script);
    EXPECT_EQ(script->status, 200);

    auto state = c.Get("/api/state");
    ASSERT_TRUE(state);
    const nlohmann::json j = nlohmann::json::parse(state->body);
    EXPECT_EQ(j["width"], 16);
    EXPECT_EQ(j["slots"][0]["algorithm"], "pt-mis");
    EXPECT_EQ(j["slots"][0]["status"], "done");
    EXPECT_EQ(j["slots"][0]["spp"], 4);
    EXPECT_FALSE(j["slots"][1]["active"]);

    auto frame = c.Get("/api/frame/a");
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->status, 200);
    const ViewSlotState a = s.slot(0);
    ASSERT_EQ(frame->body.size(), 3 * sizeof(float) * a.frame->image.pixel_count());
    EXPECT_EQ(std::memcmp(frame->body.data(), a.frame->image.data(), frame->body.size()), 0);
    EXPECT_EQ(frame->get_header_value("X-Width"), "16");
    EXPECT_EQ(frame->get_header_value("X-Frame"), std::to_string(a.frame->number));
    EXPECT_EQ(c.Get("/api/frame/b")->status, 404);   // B is not running
    EXPECT_EQ(c.Get("/api/reference")->status, 404);  // no reference
    EXPECT_EQ(c.Get("/CMakeLists.txt")->status, 404);
    EXPECT_EQ(c.Get("/etc/passwd")->status, 404);

    // Restart through the API; an unknown algorithm is a 400 that names the valid ones.
    auto restarted = c.Post("/api/render", R"({"slot": "a", "algorithm": "pt-naive"})", "application/json");
    ASSERT_TRUE(restarted);
    EXPECT_EQ(restarted->status, 200);
    ASSERT_TRUE(s.wait(0, 60));
    EXPECT_EQ(s.slot(0).algorithm, "pt-naive");
    auto bad = c.Post("/api/render", R"({"slot": "a", "algorithm": "nope"})", "application/json");
    EXPECT_EQ(bad->status, 400);
    EXPECT_NE(bad->body.find("pt-mis"), std::string::npos);
    EXPECT_EQ(c.Post("/api/render", "{", "application/json")->status, 400);
    // Not JSON: what a form on another site could post without a preflight.
    EXPECT_EQ(c.Post("/api/render", "slot=a&algorithm=lt", "application/x-www-form-urlencoded")->status, 415);
    EXPECT_EQ(s.slot(0).algorithm, "pt-naive");

    // A second server on the same port is refused (not sharing it, as SO_REUSEPORT would).
    EXPECT_THROW(ViewServer(s, "127.0.0.1", server.port()), std::runtime_error);

    // Another Host: a page elsewhere whose name was rebound to 127.0.0.1.
    auto rebound = c.Get("/api/state", {{"Host", "attacker.example:80"}});
    ASSERT_TRUE(rebound);
    EXPECT_EQ(rebound->status, 403);
}

}  // namespace
}  // namespace pathlab::test
