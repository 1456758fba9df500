// Image files: round trips through every format, and clear errors naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "image/image_io.hpp"
#include "samplers/sampler.hpp"

namespace pathlab::test {
namespace {
namespace fs = std::filesystem;

class ImageIo : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-io-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    static Image random_image(int w = 37, int h = 23) {
        Image img(w, h);
        Sampler rng(11, 0, 0);
        for (size_t i = 0; i < img.pixel_count(); ++i) {
            // Values spanning many octaves, as radiance does.
            for (int c = 0; c < 3; ++c) img[i][c] = std::exp2(rng.next1d() * 24 - 14) * rng.next1d();
        }
        img[0] = Rgb(0.0f);
        return img;
    }
    fs::path dir_;
};

TEST_F(ImageIo, ExrRoundTripIsExact) {
    const Image img = random_image();
    write_image(img, path("a.exr"));
    const Image back = read_image(path("a.exr"));
    ASSERT_EQ(back.width(), img.width());
    ASSERT_EQ(back.height(), img.height());
    for (size_t i = 0; i < img.pixel_count(); ++i) ASSERT_EQ(back[i], img[i]) << i;
}

TEST_F(ImageIo, PfmRoundTripIsExact) {
    const Image img = random_image();
    write_image(img, path("a.pfm"));
    const Image back = read_image(path("a.pfm"));
    ASSERT_EQ(back.width(), img.width());
    for (size_t i = 0; i < img.pixel_count(); ++i) ASSERT_EQ(back[i], img[i]) << i;
    // Top row first in memory, bottom row first in the file.
    std::ifstream in(path("a.pfm"), std::ios::binary);
    std::string header;
    for (int lines = 0; lines < 3;) lines += in.get() == '\n';
    float first[3];
    in.read(reinterpret_cast<char*>(first), sizeof(first));
    EXPECT_EQ(first[0], img.at(0, img.height() - 1).x);
}

TEST_F(ImageIo, HdrRoundTripIsWithinRgbePrecision) {
    const Image img = random_image();
    write_image(img, path("a.hdr"));
    const Image back = read_image(path("a.hdr"));
    ASSERT_EQ(back.width(), img.width());
    for (size_t i = 0; i < img.pixel_count(); ++i) {
        // A shared 8-bit exponent leaves 8 mantissa bits relative to the largest channel.
        const float tolerance = max_component(img[i]) / 128.0f;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(back[i][c], img[i][c], tolerance) << i;
    }
}

TEST_F(ImageIo, PngStoresTheSrgbEncoding) {
    Image img(4, 1);
    img[0] = Rgb(0.0f), img[1] = Rgb(0.18f), img[2] = Rgb(1.0f), img[3] = Rgb(7.0f, 0.5f, -1.0f);
    write_image(img, path("a.png"), 1.0f);  // one stop up
    const Image8 back = read_png8(path("a.png"));
    const Image8 expected = to_srgb8(img, 1.0f);
    EXPECT_EQ(back.rgb, expected.rgb);
    EXPECT_EQ(back.at(1, 0, 0), encode_srgb8(0.36f));
    EXPECT_EQ(back.at(3, 0, 2), 0);
}

TEST_F(ImageIo, WritingLeavesNoTemporaryFiles) {
    write_image(random_image(), path("b.exr"));
    int files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++files;
    EXPECT_EQ(files, 1);
}

TEST_F(ImageIo, ErrorsNameTheFile) {
    const auto expect_error = [](auto&& fn, const std::string& needle) {
        try {
            fn();
            ADD_FAILURE() << "no error for " << needle;
        } catch (const ImageIoError& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expect_error([&] { read_image(path("missing.exr")); }, "missing.exr");
    expect_error([&] { write_image(Image(2, 2), path("x.tiff")); }, "x.tiff");
    expect_error([&] { check_writable_image_path("/proc/pathlab/x.exr"); }, "/proc/pathlab/x.exr");
    std::ofstream(path("bad.pfm")) << "PF\n3 3\n-1\nshort";
    expect_error([&] { read_image(path("bad.pfm")); }, "bad.pfm");
    std::ofstream(path("bad.exr")) << "not an exr";
    expect_error([&] { read_image(path("bad.exr")); }, "bad.exr");
    std::ofstream(path("bad.hdr")) << "nope";
    expect_error([&] { read_image(path("bad.hdr")); }, "bad.hdr");
}

}  // namespace
}  // namespace pathlab::test
