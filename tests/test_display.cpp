// --display-server: the packets tev receives (read here by a fake tev on loopback that parses
// them as tev's src/Ipc.cpp does), the image they carry equal to the film's, and a render that
// is the same, byte for byte, with a viewer, with one that goes away and with none.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "cli_runner.hpp"
#include "fake_tev.hpp"
#include "display/display_server.hpp"
#include "display/tev_protocol.hpp"
#include "image/image_io.hpp"

namespace pathlab::test {
namespace {
namespace fs = std::filesystem;

class Display : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-display-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    static std::string bytes_of(const std::string& file) {
        std::ifstream in(file, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), {}};
    }
    fs::path dir_;
};

TEST(TevProtocol, CreateImageBytes) {
    const std::vector<std::string> channels = {"R", "G"};
    const std::vector<char> p = tev::create_image("ab", 3, 2, channels, true);
    const char expected[] = {25, 0, 0, 0, 4, 1, 'a', 'b', 0, 3, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 'R', 0, 'G', 0};
    ASSERT_EQ(p.size(), sizeof(expected));
    EXPECT_EQ(std::memcmp(p.data(), expected, sizeof(expected)), 0);
}

TEST(TevProtocol, UpdateImageCarriesTheRegion) {
    // A 2x2 region at (1, 1) of a 4-pixel-wide image of 3 channels.
    std::vector<float> image(4 * 3 * 3);
    for (size_t i = 0; i < image.size(); ++i) image[i] = float(i);
    const std::vector<std::string> channels = {"R", "G", "B"};
    const std::vector<char> bytes = tev::update_image("img", channels, 1, 1, 2, 2, image.data() + (1 * 4 + 1) * 3, 4 * 3);
    const std::vector<TevPacket> ps = parse_packets(std::string(bytes.begin(), bytes.end()));
    ASSERT_EQ(ps.size(), 1u);
    const TevPacket& p = ps[0];
    EXPECT_EQ(p.type, 6);
    EXPECT_EQ(p.name, "img");
    EXPECT_EQ(p.channels, channels);
    EXPECT_EQ(p.x, 1);
    EXPECT_EQ(p.y, 1);
    EXPECT_EQ(p.width, 2);
    EXPECT_EQ(p.height, 2);
    for (int c = 0; c < 3; ++c)
        for (int py = 0; py < 2; ++py)
            for (int px = 0; px < 2; ++px)
                EXPECT_EQ(p.data[size_t(c)][size_t(py * 2 + px)], image[size_t(((1 + py) * 4 + 1 + px) * 3 + c)]);
}

TEST(TevProtocol, AddressesAreParsed) {
    EXPECT_EQ(parse_display_address("localhost")->port, 14158);
    EXPECT_EQ(parse_display_address("localhost")->host, "localhost");
    EXPECT_EQ(parse_display_address("10.0.0.2:9000")->port, 9000);
    EXPECT_EQ(parse_display_address("[::1]:81")->host, "::1");
    EXPECT_EQ(parse_display_address("[::1]")->port, 14158);
    for (const char* bad : {"", ":14158", "host:", "host:0", "host:65536", "host:12a", "::1", "[::1", "[::1]x", "host:123456"})
        EXPECT_FALSE(parse_display_address(bad)) << bad;
}

TEST(TevProtocol, LargeFramesGoInStripes) {
    // 1500 x 600 x 3 floats = 10.8 MB: two stripes of at most 8 MiB each.
    FakeTev tev;
    DisplayFrame f{"big", 1500, 600, {"R", "G", "B"}, std::vector<float>(size_t(1500) * 600 * 3)};
    for (size_t i = 0; i < f.pixels.size(); ++i) f.pixels[i] = float(i % 1000);
    {
        DisplayServer server(*parse_display_address(tev.address()), [](const std::string&) {});
        server.post(f);
        EXPECT_TRUE(server.flush(10));
    }
    const std::vector<std::string> got = wait_for(tev, 1);
    ASSERT_EQ(got.size(), 1u);
    const std::vector<TevPacket> ps = parse_packets(got[0]);
    ASSERT_EQ(ps.size(), 3u);
    EXPECT_EQ(ps[0].type, 4);
    const int rows = tev::stripe_rows(1500, 3);
    EXPECT_EQ(rows, 466);
    EXPECT_EQ(ps[1].y, 0);
    EXPECT_EQ(ps[1].height, rows);
    EXPECT_EQ(ps[2].y, rows);
    EXPECT_EQ(ps[2].height, 600 - rows);
    for (const TevPacket& p : {ps[1], ps[2]})
        for (size_t i = 0; i < p.data[1].size(); ++i)
            ASSERT_EQ(p.data[1][i], f.pixels[(size_t(p.y) * 1500 + i) * 3 + 1]);
}

// The last update of the stream equals the image written, and the image is the same without a viewer.
void check_stream(const std::string& bytes, const Image& written, const std::string& name) {
    const std::vector<TevPacket> ps = parse_packets(bytes);
    ASSERT_GE(ps.size(), 2u);
    EXPECT_EQ(ps[0].type, 4);
    EXPECT_EQ(ps[0].name, name);
    EXPECT_EQ(ps[0].width, written.width());
    EXPECT_EQ(ps[0].height, written.height());
    EXPECT_EQ(ps[0].channels, (std::vector<std::string>{"R", "G", "B"}));
    for (size_t i = 1; i < ps.size(); ++i) {
        EXPECT_EQ(ps[i].type, 6);
        EXPECT_EQ(ps[i].name, name);
        EXPECT_EQ(ps[i].width, written.width());
    }
    const TevPacket& last = ps.back();
    ASSERT_EQ(last.y, 0);
    ASSERT_EQ(last.height, written.height());
    for (size_t i = 0; i < written.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(last.data[size_t(c)][i], written[i][c]) << "pixel " << i << " channel " << c;
}

TEST_F(Display, StreamsThePathTracersAndTheSplattingImagesAsWritten) {
    for (const char* algorithm : {"pt-mis", "lt", "vcm"}) {
        SCOPED_TRACE(algorithm);
        FakeTev tev;
        const std::vector<std::string> common = {"--scene", "4", "-a", algorithm, "--spp", "6", "--resolution", "24x16", "-q"};
        std::vector<std::string> with = common, without = common;
        with.insert(with.end(), {"-o", path("with.pfm"), "--display-server", tev.address()});
        without.insert(without.end(), {"-o", path("without.pfm")});
        const CliResult a = run(with), b = run(without);
        ASSERT_EQ(a.code, 0) << a.err;
        ASSERT_EQ(b.code, 0) << b.err;
        EXPECT_EQ(a.err, "");
        EXPECT_EQ(bytes_of(path("with.pfm")), bytes_of(path("without.pfm")));
        const std::vector<std::string> got = wait_for(tev, 1);
        ASSERT_EQ(got.size(), 1u);
        check_stream(got[0], read_image(path("with.pfm")), std::string("box-diffuse / ") + algorithm);
    }
}

TEST_F(Display, AovsGoAsExtraLayers) {
    FakeTev tev;
    const CliResult r = run({"--scene", "4", "--spp", "4", "--resolution", "12x10", "-q", "--aovs", "albedo,sample-count", "-o",
                             path("aovs.exr"), "--display-server", tev.address()});
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> got = wait_for(tev, 1);
    ASSERT_EQ(got.size(), 1u);
    const std::vector<TevPacket> ps = parse_packets(got[0]);
    ASSERT_GE(ps.size(), 2u);
    const std::vector<std::string> channels = {"R", "G", "B", "Albedo.R", "Albedo.G", "Albedo.B", "SampleCount"};
    EXPECT_EQ(ps[0].channels, channels);
    ExrExtras extras;
    const Image image = read_exr(path("aovs.exr"), extras);
    const auto albedo = std::find_if(extras.layers.begin(), extras.layers.end(), [](const auto& l) { return l.first == "Albedo"; });
    ASSERT_NE(albedo, extras.layers.end());
    const TevPacket& last = ps.back();
    ASSERT_EQ(last.channels, channels);
    for (size_t i = 0; i < image.pixel_count(); ++i) {
        for (int c = 0; c < 3; ++c) {
            ASSERT_EQ(last.data[size_t(c)][i], image[i][c]);
            ASSERT_EQ(last.data[size_t(3 + c)][i], albedo->second[i][c]) << "pixel " << i;
        }
        ASSERT_EQ(last.data[6][i], 4.0f);
    }
}

TEST_F(Display, BdptsStrategyImagesGoAsExtraLayers) {
    FakeTev tev;
    const CliResult r = run({"--scene", "4", "-a", "bdpt", "--spp", "3", "--resolution", "10x8", "-q", "--strategies", path("st"),
                             "--strategies-depth", "1", "-o", path("b.pfm"), "--display-server", tev.address()});
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> got = wait_for(tev, 1);
    ASSERT_EQ(got.size(), 1u);
    const std::vector<TevPacket> ps = parse_packets(got[0]);
    ASSERT_GE(ps.size(), 2u);
    // Paths of 0 and 1 bounces: (s, t) = (0, 2); (0, 3), (1, 2), (2, 1) (s = t = 1 is not a strategy).
    std::vector<std::string> channels = {"R", "G", "B"};
    for (const char* st : {"n0-s0-t2", "n1-s0-t3", "n1-s1-t2", "n1-s2-t1"})
        for (const char* c : {".R", ".G", ".B"}) channels.push_back(std::string(st) + c);
    const TevPacket& last = ps.back();
    EXPECT_EQ(ps[0].channels, channels);
    EXPECT_EQ(last.channels, channels);
    // The strategy images written at the end are the last frame's layers.
    const Image s12 = read_image(path("st/n1-s1-t2-weighted.exr"));
    const auto at = std::find(last.channels.begin(), last.channels.end(), "n1-s1-t2.G");
    ASSERT_NE(at, last.channels.end());
    for (size_t i = 0; i < s12.pixel_count(); ++i) ASSERT_EQ(last.data[size_t(at - last.channels.begin())][i], s12[i][1]);
}

TEST_F(Display, AViewerThatGoesAwayOrIsNotThereChangesNothing) {
    const std::vector<std::string> common = {"--scene", "4", "-a", "pt-mis", "--spp", "8", "--resolution", "24x16", "-q"};
    std::vector<std::string> reference = common;
    reference.insert(reference.end(), {"-o", path("ref.pfm")});
    ASSERT_EQ(run(reference).code, 0);
    {
        FakeTev tev(/*close_at_once=*/true);
        std::vector<std::string> args = common;
        args.insert(args.end(), {"-o", path("closed.pfm"), "--display-server", tev.address()});
        const CliResult r = run(args);
        EXPECT_EQ(r.code, 0) << r.err;
        EXPECT_GE(tev.accepted(), 1);
        EXPECT_EQ(bytes_of(path("closed.pfm")), bytes_of(path("ref.pfm")));
    }
    // A port nobody listens on (the fake tev's, once it is gone): one warning, the same image.
    int port;
    {
        FakeTev gone;
        port = gone.port();
    }
    std::vector<std::string> args = common;
    args.insert(args.end(), {"-o", path("none.pfm"), "--display-server", "127.0.0.1:" + std::to_string(port)});
    const CliResult r = run(args);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "cannot connect")) << r.err;
    EXPECT_EQ(r.err.find("display server"), r.err.rfind("display server")) << "said more than once: " << r.err;
    EXPECT_EQ(bytes_of(path("none.pfm")), bytes_of(path("ref.pfm")));
}

TEST_F(Display, ABadAddressIsAUsageError) {
    const CliResult r = run({"--scene", "4", "--spp", "1", "-o", path("x.pfm"), "--display-server", "host:99999"});
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--display-server: 'host:99999'")) << r.err;
}

TEST(DisplayServerClient, ReconnectsAndSendsTheNewestFrameAgain) {
    // The first viewer closes every connection; a later one on the same port receives the newest
    // frame, CreateImage first.
    std::vector<std::string> said;
    std::mutex m;
    auto first = std::make_unique<FakeTev>(/*close_at_once=*/true);
    const int port = first->port();
    auto server = std::make_unique<DisplayServer>(*parse_display_address(first->address()), [&](const std::string& s) {
        std::lock_guard lock(m);
        said.push_back(s);
    }, /*first_retry_seconds=*/0.01);
    DisplayFrame f{"x", 2, 1, {"R", "G", "B"}, {1, 2, 3, 4, 5, 6}};
    for (int i = 0; i < 500 && server->counters().failures == 0; ++i) {
        server->post(f);
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_GE(server->counters().failures, 1u);
    first.reset();
    FakeTev second(/*close_at_once=*/false, port);
    f.pixels[4] = 50;
    server->post(f);
    for (int i = 0; i < 1000 && server->counters().frames_sent == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_TRUE(server->flush(10));
    server.reset();
    const std::vector<std::string> got = wait_for(second, 1);
    ASSERT_EQ(got.size(), 1u);
    const std::vector<TevPacket> ps = parse_packets(got[0]);
    ASSERT_GE(ps.size(), 2u);
    EXPECT_EQ(ps[0].type, 4);
    EXPECT_EQ(ps.back().data[1][1], 50.0f);
    std::lock_guard lock(m);
    ASSERT_EQ(said.size(), 2u) << "a failure after the first is not repeated";
    EXPECT_TRUE(contains(said[0], "connection lost") || contains(said[0], "cannot connect")) << said[0];
    EXPECT_TRUE(contains(said[1], "connected")) << said[1];
}

}  // namespace
}  // namespace pathlab::test
