// Image files: round trips through every format, and clear errors naming the file.
#include <gtest/gtest.h>

#include <ImfBoxAttribute.h>
#include <ImfChannelList.h>
#include <ImfChromaticitiesAttribute.h>
#include <ImfDoubleAttribute.h>
#include <ImfEnvmapAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfIDManifestAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfKeyCodeAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfPreviewImageAttribute.h>
#include <ImfRationalAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfTimeCodeAttribute.h>
#include <ImfVecAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <stb_image.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

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

std::string file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// pathlab's own RGBE reader replaced stb_image's (which looped forever on some corrupt files);
// on every kind of scanline stb_image reads correctly (run-length encoded at widths 8-32767,
// flat otherwise) it must give the same floats, bit for bit.
TEST_F(ImageIo, HdrReaderDecodesExactlyAsStbImageDid) {
    for (const auto& [w, h] : {std::pair{5, 3}, std::pair{37, 23}, std::pair{300, 7}, std::pair{40000, 2}, std::pair{1, 1}}) {
        const Image img = random_image(w, h);
        write_image(img, path("a.hdr"));
        const std::string bytes = file_bytes(path("a.hdr"));
        int sw = 0, sh = 0, sn = 0;
        std::unique_ptr<float, void (*)(void*)> stb(
            stbi_loadf_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), int(bytes.size()), &sw, &sh, &sn, 3), stbi_image_free);
        ASSERT_TRUE(stb) << w << "x" << h;
        const Image mine = read_image(path("a.hdr"));
        ASSERT_EQ(mine.width(), sw);
        ASSERT_EQ(mine.height(), sh);
        ASSERT_EQ(std::memcmp(mine.data(), stb.get(), mine.pixel_count() * sizeof(Rgb)), 0) << w << "x" << h;
    }
}

// The original Radiance encoding, which stb_image does not read: a pixel (1, 1, 1, n) repeats
// the previous one n << s times, s growing by 8 over consecutive repeats.
TEST_F(ImageIo, HdrReaderDecodesTheOldRunLengthEncoding) {
    std::string file = "#?RGBE\nSOFTWARE=hand-made\n\n-Y 2 +X 300\n";
    const auto pixel = [&](int r, int g, int b, int e) { file += {char(r), char(g), char(b), char(e)}; };
    // Row 0: (128, 64, 32) at exponent 129, repeated 3 + (1 << 8) times, then 40 of another.
    pixel(128, 64, 32, 129);
    pixel(1, 1, 1, 3);
    pixel(1, 1, 1, 1);  // 1 << 8 more
    pixel(10, 20, 30, 130);
    pixel(1, 1, 1, 39);
    // Row 1: flat pixels.
    for (int x = 0; x < 300; ++x) pixel(x % 256, 7, 0, x % 2 ? 128 : 0);
    std::ofstream(path("old.hdr"), std::ios::binary) << file;
    const Image img = read_image(path("old.hdr"));
    ASSERT_EQ(img.width(), 300);
    for (int x = 0; x < 260; ++x) ASSERT_EQ(img.at(x, 0), Rgb(1.0f, 0.5f, 0.25f)) << x;  // 128 * 2^(129-136) = 1
    for (int x = 260; x < 300; ++x) ASSERT_EQ(img.at(x, 0), Rgb(10, 20, 30) / 64.0f) << x;  // 2^(130-136)
    for (int x = 0; x < 300; ++x) ASSERT_EQ(img.at(x, 1), x % 2 ? Rgb(float(x % 256), 7, 0) / 256.0f : Rgb(0.0f)) << x;
}

TEST_F(ImageIo, HdrHeaderVariantsAndWhatIsRefused) {
    const std::string pixels(16, '\x80');  // 4 flat pixels (128, 128, 128, 128): 0.5
    const auto read = [&](const std::string& header) {
        std::ofstream(path("v.hdr"), std::ios::binary) << header << pixels;
        return read_image(path("v.hdr"));
    };
    EXPECT_EQ(read("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 4\n").at(3, 0), Rgb(0.5f));
    EXPECT_EQ(read("#?RGBE\r\nEXPOSURE=1\r\n\r\n-Y  2\t+X 2\r\n").at(1, 1), Rgb(0.5f));  // no FORMAT, CRLF, blanks
    const auto refused = [&](const std::string& header, const std::string& needle) {
        try {
            read(header);
            ADD_FAILURE() << "accepted " << header;
        } catch (const ImageIoError& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("v.hdr"), std::string::npos) << e.what();
        }
    };
    refused("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 4\n", "cannot read HDR: unsupported pixel format '32-bit_rle_xyze'");
    refused("#?RADIANCE\n\n+Y 1 +X 4\n", "cannot read HDR: unsupported orientation '+Y 1 +X 4'");
    refused("#?RADIANCE\n\n-Y 1 +X 0\n", "cannot read HDR: invalid resolution line");
    refused("#?RADIANCE\n\n-Y 1 +X 5\n", "truncated");
    refused("P6\n", "cannot read HDR: not a Radiance HDR file");
}

// Big-endian (positive scale) and greyscale (Pf) files, as other programs write them.
TEST_F(ImageIo, PfmReadsBigEndianAndGreyscale) {
    std::string file = "Pf\n2 2\n1.0\n";
    for (const float v : {1.0f, 2.0f, 3.0f, -0.5f}) {  // bottom row first
        const uint32_t be = __builtin_bswap32(std::bit_cast<uint32_t>(v));
        file.append(reinterpret_cast<const char*>(&be), 4);
    }
    std::ofstream(path("g.pfm"), std::ios::binary) << file;
    const Image img = read_image(path("g.pfm"));
    EXPECT_EQ(img.at(0, 1), Rgb(1.0f));
    EXPECT_EQ(img.at(1, 1), Rgb(2.0f));
    EXPECT_EQ(img.at(0, 0), Rgb(3.0f));
    EXPECT_EQ(img.at(1, 0), Rgb(-0.5f));
}

// OpenEXR files of every compression, tiled and mipmapped ones, half and grey ones, with a
// data window away from the origin and heights that are no multiple of any chunk: read in
// bands by pathlab, they must equal OpenEXR's own one-shot reading.
TEST_F(ImageIo, ExrOfEveryKindReadsAsOpenExrReadsIt) {
    struct Kind {
        Imf::Compression compression;
        bool tiled, half, grey;
    };
    const Kind kinds[] = {{Imf::NO_COMPRESSION, false, false, false}, {Imf::RLE_COMPRESSION, false, false, false},
                          {Imf::ZIPS_COMPRESSION, false, true, false}, {Imf::ZIP_COMPRESSION, false, false, false},
                          {Imf::PIZ_COMPRESSION, false, true, false},  {Imf::PXR24_COMPRESSION, false, false, false},
                          {Imf::B44_COMPRESSION, false, true, false},  {Imf::B44A_COMPRESSION, false, true, true},
                          {Imf::DWAA_COMPRESSION, false, true, false}, {Imf::DWAB_COMPRESSION, false, false, false},
                          {Imf::ZIP_COMPRESSION, true, false, false},  {Imf::PIZ_COMPRESSION, true, true, true}};
    const int w = 70, h = 301;
    const Image img = random_image(w, h);
    for (const Kind& k : kinds) {
        const std::string file = path("k.exr");
        const Imath::Box2i window(Imath::V2i(-5, 17), Imath::V2i(-5 + w - 1, 17 + h - 1));
        Imf::Header header(window, window);
        header.compression() = k.compression;
        const Imf::PixelType type = k.half ? Imf::HALF : Imf::FLOAT;
        const std::vector<std::string> names = k.grey ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
        for (const std::string& n : names) header.channels().insert(n, Imf::Channel(type));
        // The source in the file's pixel type.
        std::vector<float> f(size_t(w) * h * 3);
        std::vector<half> hf(f.size());
        for (size_t i = 0; i < img.pixel_count(); ++i)
            for (int c = 0; c < 3; ++c) f[i * 3 + c] = img[i][c], hf[i * 3 + c] = half(img[i][c]);
        Imf::FrameBuffer fb;
        for (size_t c = 0; c < names.size(); ++c) {
            char* base = k.half ? reinterpret_cast<char*>(hf.data() + c) : reinterpret_cast<char*>(f.data() + c);
            const size_t s = k.half ? sizeof(half) : sizeof(float);
            fb.insert(names[c], Imf::Slice::Make(type, base, window, 3 * s, 3 * s * w));
        }
        if (k.tiled) {
            header.setTileDescription(Imf::TileDescription(16, 24, Imf::MIPMAP_LEVELS));
            Imf::TiledOutputFile out(file.c_str(), header);
            out.setFrameBuffer(fb);
            for (int level = 0; level < out.numLevels(); ++level) out.writeTiles(0, out.numXTiles(level) - 1, 0, out.numYTiles(level) - 1, level);
        } else {
            Imf::OutputFile out(file.c_str(), header);
            out.setFrameBuffer(fb);
            out.writePixels(h);
        }
        // OpenEXR's reading, all at once.
        Image expected(w, h);
        {
            Imf::InputFile in(file.c_str());
            Imf::FrameBuffer rb;
            for (int c = 0; c < 3; ++c)
                rb.insert(k.grey ? "Y" : names[size_t(c)],
                          Imf::Slice::Make(Imf::FLOAT, expected.data() + c, window, sizeof(Rgb), sizeof(Rgb) * w));
            in.setFrameBuffer(rb);
            in.readPixels(window.min.y, window.max.y);
        }
        const Image back = read_image(file);
        ASSERT_EQ(back.width(), w);
        ASSERT_EQ(back.height(), h);
        ASSERT_EQ(std::memcmp(back.data(), expected.data(), back.pixel_count() * sizeof(Rgb)), 0)
            << "compression " << int(k.compression) << (k.tiled ? " tiled" : "") << (k.half ? " half" : "") << (k.grey ? " Y" : "");
        if (k.compression == Imf::NO_COMPRESSION) {
            ASSERT_EQ(back.at(3, 4), img.at(3, 4));
        }
    }
}

// The reader checks every attribute's declared size against its type before OpenEXR reads
// the header (see scan_exr_header); files with attributes of every type OpenEXR knows, as
// other programs write them, must still read.
TEST_F(ImageIo, ExrWithAttributesOfEveryKnownTypeReads) {
    const Image img = random_image(6, 5);
    Imf::Header header(img.width(), img.height());
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    header.insert("aString", Imf::StringAttribute("written by a test"));
    header.insert("anEmptyString", Imf::StringAttribute(""));
    header.insert("strings", Imf::StringVectorAttribute({"one", "", "three"}));
    header.insert("floats", Imf::FloatVectorAttribute({1.0f, 2.0f}));
    header.insert("anInt", Imf::IntAttribute(7));
    header.insert("aDouble", Imf::DoubleAttribute(0.5));
    header.insert("aBox", Imf::Box2fAttribute(Imath::Box2f(Imath::V2f(0, 0), Imath::V2f(1, 1))));
    header.insert("aV3d", Imf::V3dAttribute(Imath::V3d(1, 2, 3)));
    header.insert("aV2i", Imf::V2iAttribute(Imath::V2i(1, 2)));
    header.insert("aMatrix", Imf::M44fAttribute(Imath::M44f()));
    header.insert("aM33d", Imf::M33dAttribute(Imath::M33d()));
    header.insert("chromaticities", Imf::ChromaticitiesAttribute(Imf::Chromaticities()));
    header.insert("aRational", Imf::RationalAttribute(Imf::Rational(1, 3)));
    header.insert("aTimeCode", Imf::TimeCodeAttribute(Imf::TimeCode(1, 2, 3, 4)));
    header.insert("aKeyCode", Imf::KeyCodeAttribute(Imf::KeyCode()));
    header.insert("envmap", Imf::EnvmapAttribute(Imf::ENVMAP_LATLONG));
    Imf::IDManifest manifest;
    manifest.add("id").setComponent("name");
    manifest[0].insert(uint64_t(1), std::string("first"));
    header.insert("idManifest", Imf::IDManifestAttribute(Imf::CompressedIDManifest(manifest)));
    Imf::PreviewImage preview(3, 2);
    header.setPreviewImage(preview);
    Imf::FrameBuffer fb;
    auto* base = const_cast<char*>(reinterpret_cast<const char*>(img.data()));
    for (int c = 0; c < 3; ++c)
        fb.insert(c == 0 ? "R" : c == 1 ? "G" : "B", Imf::Slice(Imf::FLOAT, base + c * sizeof(float), sizeof(Rgb), sizeof(Rgb) * 6));
    {
        Imf::OutputFile out(path("attributes.exr").c_str(), header);
        out.setFrameBuffer(fb);
        out.writePixels(img.height());
    }
    const Image back = read_image(path("attributes.exr"));
    ASSERT_EQ(back.pixel_count(), img.pixel_count());
    for (size_t i = 0; i < img.pixel_count(); ++i) ASSERT_EQ(back[i], img[i]) << i;
}

TEST_F(ImageIo, MemoryReadersReadAsTheFileReaders) {
    const Image img = random_image();
    for (const char* name : {"m.exr", "m.hdr", "m.pfm"}) {
        write_image(img, path(name));
        const std::string bytes = file_bytes(path(name));
        const Image a = read_image(path(name)), b = read_image_from_memory(image_format_for(name), bytes.data(), bytes.size(), name);
        ASSERT_EQ(a.width(), b.width());
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.pixel_count() * sizeof(Rgb)), 0) << name;
    }
    write_image(img, path("m.png"));
    const std::string png = file_bytes(path("m.png"));
    EXPECT_EQ(read_png8(path("m.png")).rgb, read_png8_from_memory(png.data(), png.size(), "m.png").rgb);
}

}  // namespace
}  // namespace pathlab::test
