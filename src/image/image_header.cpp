#include "image/image_header.hpp"

#include <ImfAttribute.h>
#include <ImfBoxAttribute.h>
#include <ImfChannelList.h>
#include <ImfChromaticitiesAttribute.h>
#include <ImfCompressionAttribute.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfLineOrderAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfOpaqueAttribute.h>
#include <ImfRationalAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfTileDescriptionAttribute.h>
#include <ImfVecAttribute.h>

#include <algorithm>
#include <cstring>
#include <iterator>
#include <limits>

#include <fmt/format.h>

#include "image/file_io.hpp"
#include "image/image_io.hpp"

namespace pathlab {
namespace {

// Printable text: control characters and bytes past ASCII escaped, at most 200 characters.
std::string printable(const std::string& s) {
    std::string out;
    for (const char c : s) {
        if (out.size() >= 200) return out + "...";
        const unsigned char u = static_cast<unsigned char>(c);
        out += (u >= 32 && u < 127) ? std::string(1, c) : fmt::format("\\x{:02x}", unsigned(u));
    }
    return out;
}

std::string compression_name(Imf::Compression c) {
    static const char* const names[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"};
    return size_t(c) < std::size(names) ? names[c] : fmt::format("{}", int(c));
}

// An EXR attribute's value as text (its type follows in brackets).
std::string exr_value(const Imf::Attribute& a) {
    using namespace Imf;
    if (const auto* v = dynamic_cast<const IntAttribute*>(&a)) return fmt::format("{}", v->value());
    if (const auto* v = dynamic_cast<const FloatAttribute*>(&a)) return fmt::format("{}", v->value());
    if (const auto* v = dynamic_cast<const DoubleAttribute*>(&a)) return fmt::format("{}", v->value());
    if (const auto* v = dynamic_cast<const StringAttribute*>(&a)) return printable(v->value());
    if (const auto* v = dynamic_cast<const StringVectorAttribute*>(&a)) {
        std::vector<std::string> items;
        for (const std::string& s : v->value()) items.push_back(printable(s));
        return fmt::format("[{}]", fmt::join(items, ", "));
    }
    if (const auto* v = dynamic_cast<const FloatVectorAttribute*>(&a)) return fmt::format("[{}]", fmt::join(v->value(), ", "));
    if (const auto* v = dynamic_cast<const V2iAttribute*>(&a)) return fmt::format("({}, {})", v->value().x, v->value().y);
    if (const auto* v = dynamic_cast<const V2fAttribute*>(&a)) return fmt::format("({}, {})", v->value().x, v->value().y);
    if (const auto* v = dynamic_cast<const V3iAttribute*>(&a)) return fmt::format("({}, {}, {})", v->value().x, v->value().y, v->value().z);
    if (const auto* v = dynamic_cast<const V3fAttribute*>(&a)) return fmt::format("({}, {}, {})", v->value().x, v->value().y, v->value().z);
    if (const auto* v = dynamic_cast<const Box2iAttribute*>(&a))
        return fmt::format("({}, {}) - ({}, {})", v->value().min.x, v->value().min.y, v->value().max.x, v->value().max.y);
    if (const auto* v = dynamic_cast<const Box2fAttribute*>(&a))
        return fmt::format("({}, {}) - ({}, {})", v->value().min.x, v->value().min.y, v->value().max.x, v->value().max.y);
    if (const auto* v = dynamic_cast<const CompressionAttribute*>(&a)) return compression_name(v->value());
    if (const auto* v = dynamic_cast<const LineOrderAttribute*>(&a))
        return v->value() == INCREASING_Y ? "increasing y" : v->value() == DECREASING_Y ? "decreasing y" : "random y";
    if (const auto* v = dynamic_cast<const RationalAttribute*>(&a)) return fmt::format("{}/{}", v->value().n, v->value().d);
    if (const auto* v = dynamic_cast<const ChromaticitiesAttribute*>(&a)) {
        const Chromaticities& c = v->value();
        return fmt::format("red ({}, {}), green ({}, {}), blue ({}, {}), white ({}, {})", c.red.x, c.red.y, c.green.x, c.green.y, c.blue.x,
                           c.blue.y, c.white.x, c.white.y);
    }
    if (const auto* v = dynamic_cast<const M44fAttribute*>(&a)) {
        std::vector<float> m;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) m.push_back(v->value()[i][j]);
        return fmt::format("[{}]", fmt::join(m, ", "));
    }
    if (const auto* v = dynamic_cast<const TileDescriptionAttribute*>(&a))
        return fmt::format("{}x{} tiles", v->value().xSize, v->value().ySize);
    if (const auto* v = dynamic_cast<const OpaqueAttribute*>(&a)) {
        // A type OpenEXR does not know: its bytes (as a little-endian integer when 8 or 4 long).
        const int n = v->dataSize();
        const char* d = v->data();
        if (n == 8) {
            uint64_t x = 0;
            std::memcpy(&x, d, 8);
            return fmt::format("{} (8 bytes)", x);
        }
        if (n == 4) {
            uint32_t x = 0;
            std::memcpy(&x, d, 4);
            return fmt::format("{} (4 bytes)", x);
        }
        return fmt::format("{} bytes", n);
    }
    return "(not shown)";
}

ImageHeader exr_header(const std::string& path) {
    ImageHeader h;
    h.format = "OpenEXR";
    try {
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        const Imath::Box2i dw = header.dataWindow();
        h.width = dw.max.x - dw.min.x + 1;
        h.height = dw.max.y - dw.min.y + 1;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
            const Imf::PixelType t = it.channel().type;
            h.channels.push_back(fmt::format("{} ({})", it.name(), t == Imf::FLOAT ? "float" : t == Imf::HALF ? "half" : "uint"));
        }
        for (auto it = header.begin(); it != header.end(); ++it) {
            const std::string type = it.attribute().typeName();
            if (type == "chlist") continue;  // the channels, above
            h.attributes.push_back({it.name(), fmt::format("{} [{}]", exr_value(it.attribute()), type)});
        }
    } catch (const std::exception& e) {
        throw ImageIoError(fmt::format("{}: {}", path, e.what()));
    }
    return h;
}

// The first `max` bytes of a file, read as the image readers read (io::FileSource: a named pipe,
// a device or a folder is refused, not opened and waited on).
std::string file_prefix(const std::string& path, size_t max) {
    const io::FileSource source(path);
    std::string s(size_t(std::min<uint64_t>(max, source.size())), '\0');
    source.read(0, s.data(), s.size());
    return s;
}

ImageHeader hdr_header(const std::string& path) {
    ImageHeader h;
    h.format = "Radiance RGBE";
    h.channels = {"R, G, B (shared 8-bit exponent)"};
    const std::string text = file_prefix(path, 1 << 16);
    size_t start = 0;
    for (int line = 0; start < text.size() && line < 200; ++line) {
        const size_t end = std::min(text.find('\n', start), text.size());
        const std::string l = text.substr(start, end - start);
        start = end + 1;
        if (l.empty()) {  // the blank line before the resolution line
            const size_t eol = std::min(text.find('\n', start), text.size());
            h.attributes.push_back({"resolution", printable(text.substr(start, eol - start))});
            break;
        }
        if (line == 0) continue;  // the magic "#?RADIANCE"
        const size_t eq = l.find('=');
        if (eq == std::string::npos) h.attributes.push_back({"comment", printable(l)});
        else h.attributes.push_back({printable(l.substr(0, eq)), printable(l.substr(eq + 1))});
    }
    return h;
}

ImageHeader pfm_header(const std::string& path) {
    ImageHeader h;
    h.format = "PFM";
    const std::string text = file_prefix(path, 256);
    h.channels = {text.rfind("Pf", 0) == 0 ? "Y (float)" : "R, G, B (float)"};
    // "PF\nW H\nscale\n": a negative scale means little-endian.
    size_t p = 0;
    for (int field = 0; field < 2 && p != std::string::npos; ++field) p = text.find('\n', p + 1);
    if (p != std::string::npos) {
        const size_t e = text.find('\n', p + 1);
        const std::string scale = text.substr(p + 1, e == std::string::npos ? std::string::npos : e - p - 1);
        h.attributes.push_back({"scale", printable(scale)});
        h.attributes.push_back({"byte order", scale.rfind('-', 0) == 0 ? "little-endian" : "big-endian"});
    }
    return h;
}

uint32_t big_endian32(const std::string& s, size_t at) {
    return uint32_t(uint8_t(s[at])) << 24 | uint32_t(uint8_t(s[at + 1])) << 16 | uint32_t(uint8_t(s[at + 2])) << 8 | uint32_t(uint8_t(s[at + 3]));
}

ImageHeader png_header(const std::string& path) {
    ImageHeader h;
    h.format = "PNG";
    const std::string data = file_prefix(path, std::numeric_limits<size_t>::max());
    // Chunks after the 8-byte signature: length, type, data, CRC.
    for (size_t p = 8; p + 12 <= data.size();) {
        const uint32_t len = big_endian32(data, p);
        if (len > data.size() - p - 12) break;
        const std::string type = data.substr(p + 4, 4), body = data.substr(p + 8, len);
        if (type == "IHDR" && len >= 13) {
            static const char* const colour[] = {"grey", "?", "RGB", "palette", "grey + alpha", "?", "RGBA"};
            const unsigned depth = uint8_t(body[8]), ct = uint8_t(body[9]);
            h.channels = {fmt::format("{}, {} bits per sample", ct < std::size(colour) ? colour[ct] : "?", depth)};
        } else if (type == "tEXt" || type == "iTXt") {
            const size_t nul = body.find('\0');
            h.attributes.push_back({printable(body.substr(0, nul)), nul == std::string::npos ? "" : printable(body.substr(nul + 1))});
        } else if (type == "zTXt") {
            h.attributes.push_back({printable(body.substr(0, body.find('\0'))), "(compressed text)"});
        } else if (type == "gAMA" && len == 4) {
            h.attributes.push_back({"gamma", fmt::format("{}", big_endian32(body, 0) / 100000.0)});
        } else if (type == "sRGB") {
            h.attributes.push_back({"sRGB", "yes"});
        }
        if (type == "IEND") break;
        p += 12 + size_t(len);
    }
    return h;
}

}  // namespace

ImageHeader read_image_header(const std::string& path) {
    ImageHeader h;
    switch (image_format_for(path)) {
        case ImageFormat::Exr: return exr_header(path);
        case ImageFormat::Hdr: h = hdr_header(path); break;
        case ImageFormat::Pfm: h = pfm_header(path); break;
        case ImageFormat::Png: h = png_header(path); break;
    }
    return h;
}

}  // namespace pathlab
