#include "image/image_io.hpp"

#include <Iex.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <stb_image_write.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "image/file_io.hpp"
#include "image/rgbe.hpp"
#include "image/stb_bmp.hpp"
#include "image/stb_jpeg.hpp"
#include "image/stb_png.hpp"

namespace pathlab {
namespace fs = std::filesystem;

namespace {

static_assert(std::endian::native == std::endian::little, "the PFM and EXR code assumes a little-endian host");

std::string lower_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

uint32_t le16(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8; }
uint32_t le32(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }
uint32_t be32(const uint8_t* p) { return uint32_t(p[3]) | uint32_t(p[2]) << 8 | uint32_t(p[1]) << 16 | uint32_t(p[0]) << 24; }

// ---- EXR ---------------------------------------------------------------------------------

// OpenEXR writes through this into the checked writer. Once `quiet` is set (before the
// OutputFile's destructor writes the offset table, where OpenEXR cannot let exceptions out),
// failures are only recorded, and the caller reports them.
class ExrOutput final : public Imf::OStream {
public:
    ExrOutput(io::FdWriter& w, const std::string& name) : Imf::OStream(name.c_str()), w_(w) {}
    void write(const char c[], int n) override {
        if (quiet) return w_.put(c, size_t(n));
        w_.write(c, size_t(n));
    }
    uint64_t tellp() override { return w_.position(); }
    void seekp(uint64_t pos) override {
        if (!quiet) return w_.seek(pos);
        try {
            w_.seek(pos);
        } catch (const ImageIoError&) {
        }
    }
    bool quiet = false;

private:
    io::FdWriter& w_;
};

void write_exr(const Image& img, io::FdWriter& out, const std::string& name, const ExrExtras& extras = {}) {
    try {
        Imf::Header header(img.width(), img.height());
        Imf::FrameBuffer fb;
        const size_t xs = sizeof(Rgb), ys = sizeof(Rgb) * size_t(img.width());
        const auto insert = [&](const Image& layer, const std::string& prefix) {
            if (layer.width() != img.width() || layer.height() != img.height())
                throw ImageIoError(fmt::format("{}: the layer '{}' has another size than the image", name, prefix));
            auto* base = const_cast<char*>(reinterpret_cast<const char*>(layer.data()));
            const char* names[3] = {"R", "G", "B"};
            for (int c = 0; c < 3; ++c) {
                const std::string channel = prefix.empty() ? names[c] : prefix + "." + names[c];
                header.channels().insert(channel, Imf::Channel(Imf::FLOAT));
                fb.insert(channel, Imf::Slice(Imf::FLOAT, base + size_t(c) * sizeof(float), xs, ys));
            }
        };
        insert(img, "");
        for (const auto& [layer, image] : extras.layers) insert(image, layer);
        for (const ExrChannel& c : extras.channels) {
            if (c.values.size() != img.pixel_count()) throw ImageIoError(fmt::format("{}: channel {} has the wrong size", name, c.name));
            header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
            fb.insert(c.name, Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(c.values.data())), sizeof(float),
                                         sizeof(float) * size_t(img.width())));
        }
        for (const auto& [key, value] : extras.attributes) header.insert(key, Imf::StringAttribute(value));
        ExrOutput stream(out, name);
        Imf::OutputFile file(stream, header);
        struct Quiet {  // destroyed before `file`, on every path
            ExrOutput& s;
            ~Quiet() { s.quiet = true; }
        } quiet{stream};
        file.setFrameBuffer(fb);
        file.writePixels(img.height());
    } catch (const ImageIoError&) {
        throw;
    } catch (const std::exception& e) {
        if (out.failed()) out.throw_error();
        throw ImageIoError(fmt::format("{}: cannot write EXR: {}", name, e.what()));
    }
    if (out.failed()) out.throw_error();
}

// OpenEXR reads through this from a checked source.
class ExrInput final : public Imf::IStream {
public:
    explicit ExrInput(const io::ByteSource& src) : Imf::IStream(src.name().c_str()), src_(src) {}
    bool read(char c[], int n) override {
        if (n < 0 || pos_ > src_.size() || uint64_t(n) > src_.size() - pos_)
            throw Iex::InputExc(fmt::format("unexpected end of file ({} bytes wanted at offset {}, the file has {})", n, pos_, src_.size()));
        try {
            src_.read(pos_, c, size_t(n));
        } catch (const ImageIoError& e) {
            throw Iex::InputExc(e.what());
        }
        pos_ += uint64_t(n);
        return pos_ < src_.size();
    }
    uint64_t tellg() override { return pos_; }
    void seekg(uint64_t pos) override { pos_ = pos; }  // every read checks its range
    void clear() override {}

private:
    const io::ByteSource& src_;
    uint64_t pos_ = 0;
};

struct ExrLayout {
    int64_t min_x = 0, min_y = 0, width = 0, height = 0;
    int64_t chunk_lines = 1;  // scanlines per chunk, or the tile height
};

// OpenEXR reads a known attribute type as that type, whatever size the file declares (a box2i
// is 16 bytes, a channel list ends at its empty name, a string vector is as long as its
// strings say) and goes on from where it stopped. So that it stops exactly where the declared
// size says, which is where scan_exr_header goes on, every known type's value must take
// exactly its declared size; unknown types are read as opaque bytes of that size.
void check_attribute_value(const io::ByteSource& src, uint64_t pos, const std::string& attr, const std::string& type, uint32_t len) {
    static const std::map<std::string, uint32_t> kFixed = {
        {"box2f", 16},  {"box2i", 16},  {"compression", 1}, {"chromaticities", 32}, {"deepImageState", 1}, {"double", 8},
        {"envmap", 1},  {"float", 4},   {"int", 4},         {"keycode", 28},        {"lineOrder", 1},      {"m33d", 72},
        {"m33f", 36},   {"m44d", 128},  {"m44f", 64},       {"rational", 8},        {"tiledesc", 9},       {"timecode", 8},
        {"v2d", 16},    {"v2f", 8},     {"v2i", 8},         {"v3d", 24},            {"v3f", 12},           {"v3i", 12}};
    const auto bad = [&](const std::string& why) {
        return ImageIoError(fmt::format("{}: invalid attribute '{}' ({}): {}", src.name(), attr, type, why));
    };
    if (const auto fixed = kFixed.find(type); fixed != kFixed.end()) {
        if (len != fixed->second) throw bad(fmt::format("{} bytes instead of {}", len, fixed->second));
        return;
    }
    if (type == "string") return;
    if (type == "floatvector") {
        if (len % 4 != 0) throw bad(fmt::format("{} bytes, not a whole number of floats", len));
        return;
    }
    if (type == "idmanifest") {
        if (len < 4) throw bad(fmt::format("{} bytes", len));
        return;
    }
    if (type != "chlist" && type != "stringvector" && type != "preview") return;  // opaque: read as `len` bytes
    if (len > (1u << 24)) throw bad(fmt::format("{} bytes", len));
    std::vector<uint8_t> v(len);
    src.read(pos, v.data(), v.size());
    if (type == "preview") {
        if (len < 8 || uint64_t(le32(&v[0])) * le32(&v[4]) * 4 != len - 8) throw bad(fmt::format("{} bytes do not hold its pixels", len));
    } else if (type == "stringvector") {
        for (size_t q = 0; q < v.size();) {
            if (v.size() - q < 4) throw bad("a string is cut short");
            const uint32_t n = le32(&v[q]);
            if (n > v.size() - q - 4) throw bad(fmt::format("a string of {} bytes runs past the attribute", n));
            q += 4 + n;
        }
    } else {  // chlist: channels of a name (at most 255 characters) and 16 bytes, then an empty name
        for (size_t q = 0;;) {
            const void* nul = q < v.size() ? std::memchr(&v[q], 0, std::min<size_t>(256, v.size() - q)) : nullptr;
            if (!nul) throw bad("a channel name does not end");
            const size_t name_len = size_t(static_cast<const uint8_t*>(nul) - &v[q]);
            q += name_len + 1;
            if (name_len == 0) {
                if (q != v.size()) throw bad(fmt::format("the channel list ends {} bytes before the attribute", v.size() - q));
                break;
            }
            if (v.size() - q < 16) throw bad("a channel is cut short");
            q += 16;
        }
    }
}

// Reads the header's structure before OpenEXR does, so that nothing OpenEXR allocates from it
// (offset tables, chunk and tile buffers, the image) can exceed what the file can hold or what
// the limits allow: every attribute must lie inside the file, the data window within the pixel
// limit, the chunks' offset table within the file, every decode buffer within 12 bytes per
// allowed pixel. Only single-part scanline and tiled files are read.
ExrLayout scan_exr_header(const io::ByteSource& src, const ImageReadLimits& limits) {
    const std::string& name = src.name();
    const uint64_t size = src.size();
    uint8_t head[8];
    if (size < 8) throw ImageIoError(fmt::format("{}: not an OpenEXR file (it is {} bytes long)", name, size));
    src.read(0, head, 8);
    if (le32(head) != 20000630u) throw ImageIoError(fmt::format("{}: not an OpenEXR file (no magic number)", name));
    const uint32_t version = le32(head + 4);
    if ((version & 0xff) != 2) throw ImageIoError(fmt::format("{}: unsupported file version {}", name, version & 0xff));
    const uint32_t flags = version & ~0xffu;
    constexpr uint32_t kTiled = 0x200, kLongNames = 0x400, kDeep = 0x800, kMultiPart = 0x1000;
    if (flags & ~(kTiled | kLongNames | kDeep | kMultiPart))
        throw ImageIoError(fmt::format("{}: unsupported flags 0x{:x}", name, flags));
    if (flags & (kDeep | kMultiPart))
        throw ImageIoError(fmt::format("{}: multi-part and deep OpenEXR files are not supported (only single-part scanline or tiled images)", name));
    const bool tiled = flags & kTiled;
    const size_t max_name = flags & kLongNames ? 255 : 31;

    uint64_t pos = 8;
    const auto truncated_header = [&] { return ImageIoError(fmt::format("{}: the header is truncated", name)); };
    const auto read_name = [&](const char* what) {
        char buf[257];
        const size_t n = size_t(std::min<uint64_t>(max_name + 1, size - pos));
        if (n == 0) throw truncated_header();
        src.read(pos, buf, n);
        const void* nul = std::memchr(buf, 0, n);
        if (!nul) {
            if (n < max_name + 1) throw truncated_header();
            throw ImageIoError(fmt::format("{}: invalid header: {} longer than {} characters", name, what, max_name));
        }
        std::string s(buf, size_t(static_cast<const char*>(nul) - buf));
        pos += s.size() + 1;
        return s;
    };
    const auto bad_attribute = [&](const std::string& attr, const std::string& why) {
        return ImageIoError(fmt::format("{}: invalid attribute '{}': {}", name, attr, why));
    };

    bool have_window = false, have_channels = false, have_tiles = false;
    int32_t window[4] = {0, 0, 0, 0};
    int compression = -1;
    uint32_t tile_w = 0, tile_h = 0, tile_mode = 0;
    uint64_t bytes_per_pixel = 0, channel_count = 0;
    for (;;) {
        const std::string attr = read_name("an attribute name");
        if (attr.empty()) break;
        const std::string type = read_name("an attribute type");
        if (size - pos < 4) throw truncated_header();
        uint8_t len_bytes[4];
        src.read(pos, len_bytes, 4);
        pos += 4;
        const int32_t len = int32_t(le32(len_bytes));
        if (len < 0 || uint64_t(len) > size - pos)
            throw bad_attribute(attr, fmt::format("{} bytes, more than the rest of the file ({} bytes)", len, size - pos));
        check_attribute_value(src, pos, attr, type, uint32_t(len));
        const auto value = [&](size_t expected) {
            if (size_t(len) != expected) throw bad_attribute(attr, fmt::format("{} bytes instead of {}", len, expected));
            std::vector<uint8_t> v(expected);
            src.read(pos, v.data(), expected);
            return v;
        };
        if (attr == "dataWindow") {
            if (type != "box2i") throw bad_attribute(attr, "not a box2i");
            const std::vector<uint8_t> v = value(16);
            for (int i = 0; i < 4; ++i) window[i] = int32_t(le32(&v[size_t(4 * i)]));
            have_window = true;
        } else if (attr == "compression") {
            if (type != "compression") throw bad_attribute(attr, "not a compression");
            compression = value(1)[0];
        } else if (attr == "tiles") {
            if (type != "tiledesc") throw bad_attribute(attr, "not a tiledesc");
            const std::vector<uint8_t> v = value(9);
            tile_w = le32(&v[0]), tile_h = le32(&v[4]), tile_mode = v[8];
            have_tiles = true;
        } else if (attr == "channels") {
            if (type != "chlist") throw bad_attribute(attr, "not a chlist");
            if (len > (1 << 20)) throw bad_attribute(attr, fmt::format("a channel list of {} bytes", len));
            std::vector<uint8_t> v(static_cast<size_t>(len));
            src.read(pos, v.data(), v.size());
            bytes_per_pixel = 0, channel_count = 0;
            size_t q = 0;
            for (;;) {
                const void* nul = q < v.size() ? std::memchr(&v[q], 0, v.size() - q) : nullptr;
                if (!nul) throw bad_attribute(attr, "the channel list does not end");
                const size_t name_len = size_t(static_cast<const uint8_t*>(nul) - &v[q]);
                q += name_len + 1;
                if (name_len == 0) break;
                if (v.size() - q < 16) throw bad_attribute(attr, "a channel is cut short");
                const uint32_t pixel_type = le32(&v[q]);
                const int32_t xs = int32_t(le32(&v[q + 8])), ys = int32_t(le32(&v[q + 12]));
                q += 16;
                if (pixel_type > 2) throw bad_attribute(attr, fmt::format("unknown pixel type {}", pixel_type));
                if (xs < 1 || ys < 1) throw bad_attribute(attr, fmt::format("sampling {}x{}", xs, ys));
                bytes_per_pixel += pixel_type == 1 ? 2 : 4;  // HALF, or UINT and FLOAT
                if (++channel_count > 1024) throw bad_attribute(attr, "more than 1024 channels");
            }
            have_channels = true;
        }
        pos += uint64_t(len);
    }
    const uint64_t header_end = pos;
    if (!have_window) throw ImageIoError(fmt::format("{}: invalid header: no dataWindow", name));
    if (!have_channels || channel_count == 0) throw ImageIoError(fmt::format("{}: invalid header: no channels", name));
    if (compression < 0 || compression > 9)
        throw ImageIoError(fmt::format("{}: invalid header: {} compression", name, compression < 0 ? "no" : "unknown"));
    ExrLayout layout;
    layout.min_x = window[0], layout.min_y = window[1];
    const int64_t w = int64_t(window[2]) - window[0] + 1, h = int64_t(window[3]) - window[1] + 1;
    if (w <= 0 || h <= 0) throw ImageIoError(fmt::format("{}: the data window is empty", name));
    io::check_image_size(name, uint64_t(w), uint64_t(h), limits.max_pixels, sizeof(Rgb));
    layout.width = w, layout.height = h;

    // Chunks of level 0 (at least as many as the file holds offsets for) and the largest
    // buffers OpenEXR allocates to decode one.
    double chunks = 0, buffer = 0;
    const double row_bytes = double(w) * double(bytes_per_pixel);
    if (tiled) {
        if (!have_tiles) throw ImageIoError(fmt::format("{}: invalid header: a tiled file without tiles", name));
        if (tile_w == 0 || tile_h == 0 || tile_w > 0x7fffffff || tile_h > 0x7fffffff)
            throw ImageIoError(fmt::format("{}: invalid tile size {}x{}", name, tile_w, tile_h));
        if ((tile_mode & 0x0f) > 2 || (tile_mode >> 4) > 1)
            throw ImageIoError(fmt::format("{}: invalid tile mode {}", name, tile_mode));
        chunks = std::ceil(double(w) / tile_w) * std::ceil(double(h) / tile_h);
        buffer = std::max(double(tile_w) * double(tile_h) * double(bytes_per_pixel), row_bytes * double(tile_h));
        layout.chunk_lines = std::min<int64_t>(tile_h, h);
    } else {
        static constexpr int kLinesPerChunk[10] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
        layout.chunk_lines = kLinesPerChunk[compression];
        chunks = std::ceil(double(h) / double(layout.chunk_lines));
        buffer = row_bytes * double(layout.chunk_lines);
    }
    const double after_header = double(size - header_end);
    if (chunks * 8 > after_header)
        throw ImageIoError(fmt::format("{}: truncated: the header announces {:.0f} chunks, whose offset table "
                                       "alone takes {:.0f} bytes, but {:.0f} bytes follow the header",
                                       name, chunks, chunks * 8, after_header));
    const double max_buffer = std::max(double(sizeof(Rgb)) * double(limits.max_pixels), double(64 << 20));
    if (buffer > max_buffer)
        throw ImageIoError(fmt::format("{}: a chunk of this file would take {:.1f} MiB to decode ({} channels, {} bytes "
                                       "per pixel), more than the {:.0f} MiB allowed",
                                       name, buffer / double(1 << 20), channel_count, bytes_per_pixel, max_buffer / double(1 << 20)));
    return layout;
}

Image read_exr(const io::ByteSource& src, const ImageReadLimits& limits, ExrExtras* extras = nullptr) {
    const std::string& name = src.name();
    const ExrLayout layout = scan_exr_header(src, limits);
    try {
        ExrInput stream(src);
        Imf::InputFile file(stream);
        const Imath::Box2i dw = file.header().dataWindow();
        if (dw.min.x != layout.min_x || dw.min.y != layout.min_y || int64_t(dw.max.x) - dw.min.x + 1 != layout.width ||
            int64_t(dw.max.y) - dw.min.y + 1 != layout.height)
            throw ImageIoError(fmt::format("{}: inconsistent header (two data windows?)", name));
        const Imf::ChannelList& channels = file.header().channels();
        const bool grey = !channels.findChannel("R") && channels.findChannel("Y");
        if (!grey && !(channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B")))
            throw ImageIoError(fmt::format("{}: no R, G, B (or Y) channels", name));
        const int64_t w = layout.width, h = layout.height;
        // The layers asked for: every layer with R, G and B channels, and the string attributes.
        std::vector<std::string> layers;
        if (extras) {
            for (auto a = file.header().begin(); a != file.header().end(); ++a)
                if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&a.attribute()))
                    extras->attributes.emplace_back(a.name(), text->value());
            std::set<std::string> names;
            channels.layers(names);
            for (const std::string& l : names)
                if (channels.findChannel(l + ".R") && channels.findChannel(l + ".G") && channels.findChannel(l + ".B")) layers.push_back(l);
            if (layers.size() > 16) throw ImageIoError(fmt::format("{}: more than 16 RGB layers", name));
        }
        std::vector<std::vector<Rgb>> layer_pixels(layers.size());
        // Read in bands of whole chunks, so that memory grows with the pixels actually decoded:
        // a file that claims a large image but holds few chunks fails before taking much.
        const int64_t band = layout.chunk_lines * std::max<int64_t>(1, 64 / layout.chunk_lines);
        const size_t total = size_t(w) * size_t(h);
        std::vector<Rgb> pixels;
        const char* names[3] = {"R", "G", "B"};
        for (int64_t y0 = 0; y0 < h; y0 += band) {
            const int64_t rows = std::min(band, h - y0);
            const size_t needed = size_t(y0 + rows) * size_t(w);
            if (pixels.capacity() < needed) pixels.reserve(std::min(total, std::max(needed, 2 * pixels.capacity())));
            pixels.resize(needed);
            Imf::FrameBuffer fb;
            const Imath::V2i origin(int(layout.min_x), int(layout.min_y + y0));
            auto* base = reinterpret_cast<char*>(&pixels[size_t(y0) * size_t(w)]);
            for (int c = 0; c < 3; ++c)
                fb.insert(grey ? "Y" : names[c], Imf::Slice::Make(Imf::FLOAT, base + c * sizeof(float), origin, w, rows, sizeof(Rgb),
                                                                  sizeof(Rgb) * size_t(w)));
            for (size_t l = 0; l < layers.size(); ++l) {
                layer_pixels[l].resize(needed);
                auto* lbase = reinterpret_cast<char*>(&layer_pixels[l][size_t(y0) * size_t(w)]);
                for (int c = 0; c < 3; ++c)
                    fb.insert(layers[l] + "." + names[c], Imf::Slice::Make(Imf::FLOAT, lbase + c * sizeof(float), origin, w, rows,
                                                                           sizeof(Rgb), sizeof(Rgb) * size_t(w)));
            }
            file.setFrameBuffer(fb);
            file.readPixels(int(layout.min_y + y0), int(layout.min_y + y0 + rows - 1));
        }
        for (size_t l = 0; l < layers.size(); ++l) extras->layers.emplace_back(layers[l], Image(int(w), int(h), std::move(layer_pixels[l])));
        return Image(int(w), int(h), std::move(pixels));
    } catch (const ImageIoError&) {
        throw;
    } catch (const std::exception& e) {
        throw ImageIoError(fmt::format("{}: {}", name, e.what()));
    }
}

// ---- PFM ---------------------------------------------------------------------------------

void write_pfm(const Image& img, io::FdWriter& out) {
    // Scale -1 means little-endian; rows are stored bottom row first.
    const std::string header = fmt::format("PF\n{} {}\n-1.0\n", img.width(), img.height());
    out.write(header.data(), header.size());
    for (int y = img.height() - 1; y >= 0; --y) out.write(&img.at(0, y), sizeof(Rgb) * size_t(img.width()));
}

Image read_pfm(const io::ByteSource& src, const ImageReadLimits& limits) {
    const std::string& name = src.name();
    // The header: "PF" or "Pf", width, height, scale, separated by white space, then one
    // white-space byte before the raster. Every token is bounded, and so is the header.
    constexpr size_t kMaxHeader = 256;
    char head[kMaxHeader];
    const size_t n = size_t(std::min<uint64_t>(src.size(), kMaxHeader));
    src.read(0, head, n);
    size_t pos = 0;
    const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    const auto token = [&](const char* what, size_t max_len) {
        while (pos < n && space(head[pos])) ++pos;
        const size_t start = pos;
        while (pos < n && !space(head[pos]) && pos - start <= max_len) ++pos;
        if (pos == start || pos == n) {
            if (n < kMaxHeader) throw ImageIoError(fmt::format("{}: the header ends before its {}", name, what));
            throw ImageIoError(fmt::format("{}: no {} in the first {} bytes", name, what, kMaxHeader));
        }
        if (pos - start > max_len)
            throw ImageIoError(fmt::format("{}: the header's {} is longer than {} characters", name, what, max_len));
        return std::string(head + start, pos - start);
    };
    if (n < 3 || head[0] != 'P' || (head[1] != 'F' && head[1] != 'f') || !space(head[2]))
        throw ImageIoError(fmt::format("{}: not a PFM file (it must begin with PF or Pf)", name));
    const int channels = head[1] == 'F' ? 3 : 1;
    pos = 2;
    const auto dimension = [&](const char* what) {
        const std::string t = token(what, 9);
        if (!std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; }) || std::stol(t) == 0)
            throw ImageIoError(fmt::format("{}: {} '{}' is not a positive number", name, what, t));
        return std::stol(t);
    };
    const long w = dimension("width"), h = dimension("height");
    const std::string scale_text = token("scale", 32);
    char* end = nullptr;
    errno = 0;
    const double scale = std::strtod(scale_text.c_str(), &end);
    if (end != scale_text.c_str() + scale_text.size() || !std::isfinite(scale) || scale == 0)
        throw ImageIoError(fmt::format("{}: scale '{}' is not a non-zero number", name, scale_text));
    ++pos;  // the single white-space byte before the raster (token() stopped on it)
    io::check_image_size(name, uint64_t(w), uint64_t(h), limits.max_pixels, sizeof(Rgb));
    const uint64_t row_bytes = uint64_t(w) * uint64_t(channels) * sizeof(float);
    const uint64_t raster = row_bytes * uint64_t(h);
    if (src.size() - pos < raster)
        throw ImageIoError(fmt::format("{}: truncated: the header says {}x{} ({} bytes of pixels) but {} bytes "
                                       "follow it",
                                       name, w, h, raster, src.size() - pos));
    const bool file_little = scale < 0;
    Image img(static_cast<int>(w), static_cast<int>(h));
    std::vector<float> row(size_t(w) * size_t(channels));
    for (long r = 0; r < h; ++r) {
        src.read(pos + uint64_t(r) * row_bytes, row.data(), size_t(row_bytes));
        if (!file_little)
            for (float& f : row) f = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<uint32_t>(f)));
        const int y = int(h - 1 - r);
        for (int x = 0; x < int(w); ++x) {
            const float* p = &row[size_t(x) * size_t(channels)];
            img.at(x, y) = channels == 3 ? Rgb(p[0], p[1], p[2]) : Rgb(p[0]);
        }
    }
    return img;
}

// ---- PNG and HDR through stb -------------------------------------------------------------

void stb_write_callback(void* context, void* data, int size) {
    static_cast<io::FdWriter*>(context)->put(data, size_t(size));
}

void write_png(const Image8& img, io::FdWriter& out, const std::string& name) {
    if (!stbi_write_png_to_func(stb_write_callback, &out, img.width, img.height, 3, img.rgb.data(), img.width * 3) && !out.failed())
        throw ImageIoError(fmt::format("{}: cannot encode PNG", name));
    if (out.failed()) out.throw_error();
}

void write_hdr(const Image& img, io::FdWriter& out, const std::string& name) {
    if (!stbi_write_hdr_to_func(stb_write_callback, &out, img.width(), img.height(), 3, img.data()) && !out.failed())
        throw ImageIoError(fmt::format("{}: cannot encode HDR", name));
    if (out.failed()) out.throw_error();
}

Image8 read_png(const io::ByteSource& src, const ImageReadLimits& limits) {
    const std::string& name = src.name();
    // The signature and IHDR (which stb_image also insists on), read here to check the size
    // before stb allocates anything.
    uint8_t head[33];
    static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (src.size() < 8) throw ImageIoError(fmt::format("{}: not a PNG file (it is {} bytes long)", name, src.size()));
    src.read(0, head, 8);
    if (std::memcmp(head, kSignature, 8) != 0) throw ImageIoError(fmt::format("{}: not a PNG file (no PNG signature)", name));
    if (src.size() < sizeof head) throw ImageIoError(fmt::format("{}: truncated in its header", name));
    src.read(0, head, sizeof head);
    if (be32(head + 8) != 13 || std::memcmp(head + 12, "IHDR", 4) != 0)
        throw ImageIoError(fmt::format("{}: it does not begin with an IHDR chunk", name));
    const uint64_t w = be32(head + 16), h = be32(head + 20);
    const unsigned depth = head[24], colour = head[25];
    io::check_image_size(name, w, h, limits.max_pixels, 3);
    static const unsigned kChannels[7] = {1, 0, 3, 1, 2, 0, 4};
    const unsigned channels = colour <= 6 ? kChannels[colour] : 0;
    if (channels == 0 || !(depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16))
        throw ImageIoError(fmt::format("{}: invalid colour type {} at {} bits", name, colour, depth));
    if (src.size() > uint64_t(INT32_MAX)) throw ImageIoError(fmt::format("{}: files over 2 GiB are not read", name));
    // Deflate expands at most 1032 times (a 258-byte match in 2 bits), so the file must hold
    // at least 1/1032 of the pixel data; otherwise it cannot be complete.
    const double pixel_bytes = double(w) * double(h) * channels * depth / 8;
    if (double(src.size()) * 1032 + 4096 < pixel_bytes)
        throw ImageIoError(fmt::format("{}: truncated: {} bytes cannot hold {}x{} pixels", name, src.size(), w, h));
    const io::Bytes bytes(src, src.size());
    // stb_image passes a null buffer to memcpy for an empty IDAT chunk before the first
    // non-empty one (undefined behaviour, found by the fuzzer); empty IDAT chunks carry no
    // data, so they are left out of what stb sees.
    std::vector<uint8_t> without_empty_idat;
    const uint8_t* png = bytes.data();
    size_t png_size = bytes.size();
    for (size_t pos = 8; png_size - pos >= 8;) {
        const uint32_t len = be32(png + pos);
        if (len == 0 && std::memcmp(png + pos + 4, "IDAT", 4) == 0) {
            if (without_empty_idat.empty()) without_empty_idat.assign(png, png + png_size);
            const size_t chunk = std::min<size_t>(12, png_size - pos);  // its CRC may be cut off
            without_empty_idat.erase(without_empty_idat.begin() + ptrdiff_t(pos), without_empty_idat.begin() + ptrdiff_t(pos + chunk));
            png = without_empty_idat.data(), png_size = without_empty_idat.size();
            continue;
        }
        if (std::memcmp(png + pos + 4, "IEND", 4) == 0 || uint64_t(len) + 12 > png_size - pos) break;  // the rest is stb's
        pos += 12 + size_t(len);
    }
    // Everything stb needs: the compressed data, the inflated rows (up to 8 bytes per pixel
    // plus a filter byte per row and pass), the decoded and the converted image.
    const size_t budget = bytes.size() + size_t(24 * w * h + 16 * h) + (size_t(4) << 20);
    Image8 img;
    const io::PngDecodeResult r = io::decode_png_rgb8(png, png_size, budget, img);
    if (!r.ok) {
        if (r.over_budget)
            throw ImageIoError(fmt::format("{}: its compressed data inflate to more than a {}x{} image holds (corrupt?)", name, w, h));
        throw ImageIoError(fmt::format("{}: {}", name, r.error));
    }
    return img;
}

// stb's decode of a w x h image whose headers pathlab has checked (JPEG, BMP): its failure, or
// memory beyond the budget, or another size than the headers' (`unit`: what they call the
// image), as an ImageIoError naming the file.
template <typename Decode>
Image8 decoded_within_budget(const std::string& name, uint64_t w, uint64_t h, const char* unit, Decode&& decode) {
    Image8 img;
    const io::PngDecodeResult r = decode(img);
    if (!r.ok) {
        if (r.over_budget) throw ImageIoError(fmt::format("{}: decoding it would take more memory than a {}x{} image needs (corrupt?)", name, w, h));
        throw ImageIoError(fmt::format("{}: {}", name, r.error));
    }
    if (uint64_t(img.width) != w || uint64_t(img.height) != h)
        throw ImageIoError(fmt::format("{}: corrupt: decoded {}x{} pixels for a {}x{} {}", name, img.width, img.height, w, h, unit));
    return img;
}

// ---- JPEG through stb ----------------------------------------------------------------------

uint32_t be16(const uint8_t* p) { return uint32_t(p[0]) << 8 | uint32_t(p[1]); }

// The markers up to the first scan are read here (stb_image reads them again): the frame's
// size is checked before stb allocates anything, the codings stb does not decode are named,
// and a file without its end-of-image marker is refused as truncated (stb would fill the
// missing part of the image with grey and succeed).
Image8 read_jpeg(const io::ByteSource& src, const ImageReadLimits& limits) {
    const std::string& name = src.name();
    if (src.size() < 4) throw ImageIoError(fmt::format("{}: not a JPEG file (it is {} bytes long)", name, src.size()));
    uint8_t head[2];
    src.read(0, head, 2);
    if (head[0] != 0xff || head[1] != 0xd8) throw ImageIoError(fmt::format("{}: not a JPEG file (no start-of-image marker)", name));
    if (src.size() > uint64_t(INT32_MAX)) throw ImageIoError(fmt::format("{}: files over 2 GiB are not read", name));
    const io::Bytes bytes(src, src.size());
    const uint8_t* b = bytes.data();
    const size_t n = bytes.size();
    const auto truncated = [&](const char* where) { return ImageIoError(fmt::format("{}: truncated: the file ends {}", name, where)); };
    uint64_t w = 0, h = 0;
    size_t pos = 2, scan = 0;
    while (scan == 0) {
        if (pos >= n) throw truncated("before its image data");
        if (b[pos] != 0xff) throw ImageIoError(fmt::format("{}: corrupt: no marker at byte {} (0x{:02x})", name, pos, b[pos]));
        while (pos < n && b[pos] == 0xff) ++pos;  // fill bytes
        if (pos >= n) throw truncated("in a marker");
        const unsigned m = b[pos++];
        if (m == 0xd8 || m == 0x01 || (m >= 0xd0 && m <= 0xd7)) continue;  // markers without a segment
        if (m == 0xd9) throw ImageIoError(fmt::format("{}: the image ends before any image data", name));
        if (n - pos < 2) throw truncated("in a segment's length");
        const size_t len = be16(b + pos);
        if (len < 2) throw ImageIoError(fmt::format("{}: corrupt: a segment of length {}", name, len));
        if (len > n - pos) throw truncated(fmt::format("inside a segment of {} bytes", len).c_str());
        const bool frame = m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc;
        if (frame) {
            if (len < 8) throw ImageIoError(fmt::format("{}: corrupt: a frame header of {} bytes", name, len));
            if (m != 0xc0 && m != 0xc1 && m != 0xc2) {
                const char* kind = m == 0xc3 ? "lossless" : (m >= 0xc9 ? "arithmetic-coded" : "hierarchical");
                throw ImageIoError(fmt::format("{}: unsupported JPEG coding: {} (baseline and progressive JPEGs are read)", name, kind));
            }
            const unsigned precision = b[pos + 2], components = b[pos + 7];
            h = be16(b + pos + 3), w = be16(b + pos + 5);
            if (precision != 8) throw ImageIoError(fmt::format("{}: unsupported JPEG: {} bits per sample (8 are read)", name, precision));
            if (h == 0) throw ImageIoError(fmt::format("{}: unsupported JPEG: its height is given after the image data (DNL)", name));
            if (components != 1 && components != 3 && components != 4)
                throw ImageIoError(fmt::format("{}: unsupported JPEG: {} components (1, 3 or 4 are read)", name, components));
            io::check_image_size(name, w, h, limits.max_pixels, 3);
        }
        if (m == 0xda) {
            if (w == 0) throw ImageIoError(fmt::format("{}: corrupt: image data before the frame header", name));
            scan = pos + len;
        }
        pos += len;
    }
    // Every 8x8 block of the first scan takes at least one bit, so a complete file holds at
    // least one byte per 512 pixels.
    if (double(n) * 512 + 4096 < double(w) * double(h))
        throw ImageIoError(fmt::format("{}: truncated: {} bytes cannot hold {}x{} pixels", name, n, w, h));
    bool end = false;
    for (size_t i = n - 1; i > scan && !end; --i) end = b[i - 1] == 0xff && b[i] == 0xd9;
    if (!end) throw truncated("before its end-of-image marker");
    // Everything stb needs: the file, per component the decoded samples and (progressive) the
    // coefficients, at most four components padded to whole 32x32 blocks, and the RGB image.
    const size_t budget = n + size_t(40 * (w + 32) * (h + 32)) + (size_t(4) << 20);
    return decoded_within_budget(name, w, h, "frame", [&](Image8& img) { return io::decode_jpeg_rgb8(b, n, budget, img); });
}

// ---- BMP ---------------------------------------------------------------------------------
// The headers are read here first (the file header, then the core or info header) and the
// pixels' size checked against the limits and, uncompressed, against the file's length, before
// stb_image decodes it within a budget.
Image8 read_bmp(const io::ByteSource& src, const ImageReadLimits& limits) {
    const std::string& name = src.name();
    if (src.size() < 26) throw ImageIoError(fmt::format("{}: not a BMP file (it is {} bytes long)", name, src.size()));
    if (src.size() > uint64_t(INT32_MAX)) throw ImageIoError(fmt::format("{}: files over 2 GiB are not read", name));
    const io::Bytes bytes(src, src.size());
    const uint8_t* b = bytes.data();
    const size_t n = bytes.size();
    if (b[0] != 'B' || b[1] != 'M') throw ImageIoError(fmt::format("{}: not a BMP file (no 'BM' signature)", name));
    const uint32_t offset = le32(b + 10), header = le32(b + 14);
    int64_t w = 0, h = 0;
    uint32_t bpp = 0, compression = 0;
    if (header == 12) {  // OS/2 core header
        w = le16(b + 18), h = le16(b + 20), bpp = le16(b + 24);
    } else if (header >= 40 && header <= 124) {
        if (n < 14 + size_t(header)) throw ImageIoError(fmt::format("{}: truncated: the file ends inside its header", name));
        w = int32_t(le32(b + 18)), h = int32_t(le32(b + 22)), bpp = le16(b + 28), compression = le32(b + 30);
    } else {
        throw ImageIoError(fmt::format("{}: unsupported BMP header of {} bytes (12 and 40 to 124 are read)", name, header));
    }
    if (bpp != 1 && bpp != 4 && bpp != 8 && bpp != 16 && bpp != 24 && bpp != 32)
        throw ImageIoError(fmt::format("{}: unsupported BMP: {} bits per pixel (1, 4, 8, 16, 24 or 32 are read)", name, bpp));
    if (compression != 0 && compression != 3)
        throw ImageIoError(fmt::format("{}: unsupported BMP compression {} (uncompressed and bit fields are read; not RLE)", name, compression));
    if (w <= 0 || h == 0) throw ImageIoError(fmt::format("{}: corrupt: a {}x{} image", name, w, h));
    const uint64_t height = uint64_t(h < 0 ? -h : h), width = uint64_t(w);
    io::check_image_size(name, width, height, limits.max_pixels, 3);
    const uint64_t row = (uint64_t(bpp) * width + 31) / 32 * 4;
    if (offset > n || row * height > n - offset)
        throw ImageIoError(fmt::format("{}: truncated: {} bytes cannot hold {}x{} pixels of {} bits from byte {}", name, n, width, height, bpp, offset));
    const size_t budget = n + size_t(4 * width * height) + (size_t(4) << 20);
    return decoded_within_budget(name, width, height, "image", [&](Image8& img) { return io::decode_bmp_rgb8(b, n, budget, img); });
}

// Runs a reader, giving each of its errors as "NAME: cannot read FORMAT: reason".
template <typename Read>
auto reading(const io::ByteSource& src, const char* format, Read&& read) -> decltype(read()) {
    try {
        return read();
    } catch (const ImageIoError& e) {
        const std::string what = e.what(), prefix = src.name() + ": ";
        if (what.rfind(prefix, 0) != 0) throw;
        throw ImageIoError(fmt::format("{}cannot read {}: {}", prefix, format, what.substr(prefix.size())));
    }
}

Image read_from(ImageFormat format, const io::ByteSource& src, const ImageReadLimits& limits) {
    switch (format) {
        case ImageFormat::Exr: return reading(src, "EXR", [&] { return read_exr(src, limits); });
        case ImageFormat::Hdr: return reading(src, "HDR", [&] { return io::read_rgbe(src, limits); });
        case ImageFormat::Pfm: return reading(src, "PFM", [&] { return read_pfm(src, limits); });
        case ImageFormat::Png: break;
    }
    throw ImageIoError(fmt::format("{}: PNG is 8-bit display data, not a linear HDR image (use .exr, .hdr or .pfm)", src.name()));
}

Image8 read_png8_from(const io::ByteSource& src, const ImageReadLimits& limits) {
    return reading(src, "PNG", [&] { return read_png(src, limits); });
}

Image8 read_jpeg8_from(const io::ByteSource& src, const ImageReadLimits& limits) {
    return reading(src, "JPEG", [&] { return read_jpeg(src, limits); });
}

Image8 read_bmp8_from(const io::ByteSource& src, const ImageReadLimits& limits) {
    return reading(src, "BMP", [&] { return read_bmp(src, limits); });
}

void write_encoded(const Image& img, ImageFormat format, io::FdWriter& out, const std::string& name, float png_exposure) {
    switch (format) {
        case ImageFormat::Exr: return write_exr(img, out, name);
        case ImageFormat::Hdr: return write_hdr(img, out, name);
        case ImageFormat::Pfm: return write_pfm(img, out);
        case ImageFormat::Png: return write_png(to_srgb8(img, png_exposure), out, name);
    }
}

}  // namespace

ImageFormat image_format_for(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".exr") return ImageFormat::Exr;
    if (ext == ".hdr") return ImageFormat::Hdr;
    if (ext == ".pfm") return ImageFormat::Pfm;
    if (ext == ".png") return ImageFormat::Png;
    throw ImageIoError(fmt::format("{}: unknown image extension '{}' (supported: .exr, .hdr, .pfm, .png)", path, ext));
}

std::string temporary_prefix_for(const std::string& path) { return io::temporary_prefix(path); }

void check_writable_image_path(const std::string& path) {
    image_format_for(path);
    if (fs::is_directory(path)) throw ImageIoError(fmt::format("{}: is a directory, not an image file name", path));
    io::probe_writable(path);
}

void check_writable_path(const std::string& path) {
    if (fs::is_directory(path)) throw ImageIoError(fmt::format("{}: is a directory, not a file name", path));
    io::probe_writable(path);
}

void write_png8(const Image8& img, const std::string& path) {
    io::write_file_atomically(path, [&](io::FdWriter& out) { write_png(img, out, path); });
}

void write_image(const Image& img, const std::string& path, float png_exposure) {
    const ImageFormat format = image_format_for(path);
    io::write_file_atomically(path, [&](io::FdWriter& out) { write_encoded(img, format, out, path, png_exposure); });
}

void write_exr(const Image& img, const ExrExtras& extras, const std::string& path) {
    if (image_format_for(path) != ImageFormat::Exr) throw ImageIoError(fmt::format("{}: layers and attributes need an .exr file", path));
    io::write_file_atomically(path, [&](io::FdWriter& out) { write_exr(img, out, path, extras); });
}

Image read_exr(const std::string& path, ExrExtras& extras, const ImageReadLimits& limits) {
    if (image_format_for(path) != ImageFormat::Exr) throw ImageIoError(fmt::format("{}: not an .exr file", path));
    const io::FileSource src(path);
    return reading(src, "EXR", [&] { return read_exr(src, limits, &extras); });
}

void write_text_file(const std::string& path, const std::string& text) {
    io::write_file_atomically(path, [&](io::FdWriter& out) { out.write(text.data(), text.size()); });
}

void write_image_to_fd(const Image& img, ImageFormat format, int fd, const std::string& name, float png_exposure) {
    io::FdWriter out(fd, name);
    write_encoded(img, format, out, name, png_exposure);
    out.flush();
}

void write_png8_to_fd(const Image8& img, int fd, const std::string& name) {
    io::FdWriter out(fd, name);
    write_png(img, out, name);
    out.flush();
}

void write_text_to_fd(const std::string& text, int fd, const std::string& name) {
    io::FdWriter out(fd, name);
    out.write(text.data(), text.size());
    out.flush();
}

Image read_image(const std::string& path, const ImageReadLimits& limits) {
    const io::FileSource src(path);
    return read_from(image_format_for(path), src, limits);
}

Image8 read_png8(const std::string& path, const ImageReadLimits& limits) { return read_png8_from(io::FileSource(path), limits); }

Image read_image_from_memory(ImageFormat format, const void* data, size_t size, const std::string& name, const ImageReadLimits& limits) {
    return read_from(format, io::MemorySource(data, size, name), limits);
}

Image8 read_png8_from_memory(const void* data, size_t size, const std::string& name, const ImageReadLimits& limits) {
    return read_png8_from(io::MemorySource(data, size, name), limits);
}

Image8 read_jpeg8(const std::string& path, const ImageReadLimits& limits) { return read_jpeg8_from(io::FileSource(path), limits); }

Image8 read_jpeg8_from_memory(const void* data, size_t size, const std::string& name, const ImageReadLimits& limits) {
    return read_jpeg8_from(io::MemorySource(data, size, name), limits);
}

Image8 read_bmp8(const std::string& path, const ImageReadLimits& limits) { return read_bmp8_from(io::FileSource(path), limits); }

Image8 read_bmp8_from_memory(const void* data, size_t size, const std::string& name, const ImageReadLimits& limits) {
    return read_bmp8_from(io::MemorySource(data, size, name), limits);
}

}  // namespace pathlab
