#include "image/image_io.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <vector>

#include <fmt/format.h>

namespace pathlab {
namespace fs = std::filesystem;

namespace {

std::string lower_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

// A unique temporary name next to `path`, so the final rename stays on one file system.
std::string temporary_path_for(const std::string& path) {
    static std::atomic<unsigned> counter{0};
    const fs::path p(path);
    const std::string name = fmt::format(".{}.tmp{}-{}", p.filename().string(), getpid(), counter++);
    return (p.parent_path() / name).string();
}

void ensure_parent_directory(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty()) return;
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) throw ImageIoError(fmt::format("{}: cannot create directory {}: {}", path, parent.string(), ec.message()));
}

// Runs `write(tmp)` and renames tmp onto path; removes tmp on any failure.
template <typename WriteFn>
void write_atomically(const std::string& path, WriteFn&& write) {
    ensure_parent_directory(path);
    const std::string tmp = temporary_path_for(path);
    try {
        write(tmp);
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw ImageIoError(fmt::format("{}: cannot write: {}", path, ec.message()));
    }
}

void write_exr(const Image& img, const std::string& path) {
    Imf::Header header(img.width(), img.height());
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    auto* base = const_cast<char*>(reinterpret_cast<const char*>(img.data()));
    const size_t xs = sizeof(Rgb), ys = sizeof(Rgb) * size_t(img.width());
    fb.insert("R", Imf::Slice(Imf::FLOAT, base + 0 * sizeof(float), xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + 1 * sizeof(float), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(img.height());
}

Image read_exr(const std::string& path) {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    const Imf::ChannelList& channels = file.header().channels();
    const bool grey = !channels.findChannel("R") && channels.findChannel("Y");
    if (!grey && !(channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B")))
        throw ImageIoError(fmt::format("{}: EXR has no R,G,B (or Y) channels", path));
    Image img(w, h);
    Imf::FrameBuffer fb;
    // Slices are addressed relative to the data window's origin.
    char* base = reinterpret_cast<char*>(img.data()) -
                 (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * w) * ptrdiff_t(sizeof(Rgb));
    const size_t xs = sizeof(Rgb), ys = sizeof(Rgb) * size_t(w);
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
        fb.insert(grey ? "Y" : names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
}

void write_pfm(const Image& img, const std::string& path) {
    std::ofstream out(path, std::ios::binary);
    if (!out) throw ImageIoError(fmt::format("{}: cannot open for writing", path));
    // Scale -1 means little-endian; rows are stored bottom row first.
    out << "PF\n" << img.width() << " " << img.height() << "\n-1.0\n";
    static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian host");
    for (int y = img.height() - 1; y >= 0; --y)
        out.write(reinterpret_cast<const char*>(&img.at(0, y)), std::streamsize(sizeof(Rgb)) * img.width());
    if (!out) throw ImageIoError(fmt::format("{}: write failed", path));
}

Image read_pfm(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImageIoError(fmt::format("{}: cannot open", path));
    std::string magic;
    int w = 0, h = 0;
    double scale = 0;
    in >> magic >> w >> h >> scale;
    if (!in || (magic != "PF" && magic != "Pf") || w <= 0 || h <= 0 || scale == 0 || w > 1 << 16 || h > 1 << 16)
        throw ImageIoError(fmt::format("{}: not a valid PFM header", path));
    in.get();  // the single whitespace byte before the raster
    const int channels = magic == "PF" ? 3 : 1;
    std::vector<float> raw(size_t(w) * size_t(h) * size_t(channels));
    in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size() * sizeof(float)));
    if (!in) throw ImageIoError(fmt::format("{}: PFM raster is truncated", path));
    const bool file_little = scale < 0;
    if (file_little != (std::endian::native == std::endian::little))
        for (float& f : raw) f = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<uint32_t>(f)));
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float* p = &raw[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * size_t(channels)];
            img.at(x, y) = channels == 3 ? Rgb(p[0], p[1], p[2]) : Rgb(p[0]);
        }
    return img;
}

Image read_hdr(const std::string& path) {
    int w = 0, h = 0, n = 0;
    if (!stbi_is_hdr(path.c_str())) throw ImageIoError(fmt::format("{}: not a Radiance HDR file", path));
    std::unique_ptr<float, void (*)(void*)> data(stbi_loadf(path.c_str(), &w, &h, &n, 3), stbi_image_free);
    if (!data) throw ImageIoError(fmt::format("{}: cannot read HDR: {}", path, stbi_failure_reason()));
    Image img(w, h);
    std::memcpy(img.data(), data.get(), img.pixel_count() * sizeof(Rgb));
    return img;
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

void check_writable_image_path(const std::string& path) {
    image_format_for(path);
    if (fs::is_directory(path)) throw ImageIoError(fmt::format("{}: is a directory, not an image file name", path));
    ensure_parent_directory(path);
    const std::string tmp = temporary_path_for(path);
    {
        std::ofstream probe(tmp, std::ios::binary);
        if (!probe) throw ImageIoError(fmt::format("{}: cannot write to this location", path));
    }
    std::error_code ec;
    fs::remove(tmp, ec);
}

void write_png8(const Image8& img, const std::string& path) {
    write_atomically(path, [&](const std::string& tmp) {
        if (!stbi_write_png(tmp.c_str(), img.width, img.height, 3, img.rgb.data(), img.width * 3))
            throw ImageIoError(fmt::format("{}: cannot write PNG", path));
    });
}

void write_image(const Image& img, const std::string& path, float png_exposure) {
    const ImageFormat format = image_format_for(path);
    if (format == ImageFormat::Png) return write_png8(to_srgb8(img, png_exposure), path);
    write_atomically(path, [&](const std::string& tmp) {
        switch (format) {
            case ImageFormat::Exr:
                try {
                    write_exr(img, tmp);
                } catch (const std::exception& e) {
                    throw ImageIoError(fmt::format("{}: cannot write EXR: {}", path, e.what()));
                }
                break;
            case ImageFormat::Hdr:
                if (!stbi_write_hdr(tmp.c_str(), img.width(), img.height(), 3, img.data()))
                    throw ImageIoError(fmt::format("{}: cannot write HDR", path));
                break;
            case ImageFormat::Pfm: write_pfm(img, tmp); break;
            case ImageFormat::Png: break;
        }
    });
}

Image read_image(const std::string& path) {
    if (!fs::exists(path)) throw ImageIoError(fmt::format("{}: no such file", path));
    switch (image_format_for(path)) {
        case ImageFormat::Exr:
            try {
                return read_exr(path);
            } catch (const ImageIoError&) {
                throw;
            } catch (const std::exception& e) {
                throw ImageIoError(fmt::format("{}: cannot read EXR: {}", path, e.what()));
            }
        case ImageFormat::Hdr: return read_hdr(path);
        case ImageFormat::Pfm: return read_pfm(path);
        case ImageFormat::Png: break;
    }
    throw ImageIoError(fmt::format("{}: PNG is 8-bit display data, not a linear HDR image (use .exr, .hdr or .pfm)", path));
}

Image8 read_png8(const std::string& path) {
    int w = 0, h = 0, n = 0;
    std::unique_ptr<unsigned char, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &n, 3), stbi_image_free);
    if (!data) throw ImageIoError(fmt::format("{}: cannot read PNG: {}", path, stbi_failure_reason()));
    Image8 img{w, h, std::vector<uint8_t>(data.get(), data.get() + size_t(w) * size_t(h) * 3)};
    return img;
}

void write_text_file(const std::string& path, const std::string& text) {
    write_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        if (!out) throw ImageIoError(fmt::format("{}: cannot write", path));
    });
}

}  // namespace pathlab
