#include "image/rgbe.hpp"

#include <cmath>
#include <cstring>
#include <string_view>
#include <vector>

#include <fmt/format.h>

namespace pathlab::io {
namespace {

constexpr size_t kMaxHeaderBytes = size_t(1) << 16;

struct RgbeHeader {
    int width = 0, height = 0;
    size_t data_start = 0;  // offset of the first scanline
};

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// A positive decimal number of at most 9 digits.
bool parse_dimension(std::string_view s, int& out) {
    if (s.empty() || s.size() > 9) return false;
    int v = 0;
    for (const char c : s) {
        if (c < '0' || c > '9') return false;
        v = v * 10 + (c - '0');
    }
    out = v;
    return v > 0;
}

RgbeHeader parse_header(const uint8_t* data, size_t size, uint64_t file_size, const std::string& name) {
    const auto* text = reinterpret_cast<const char*>(data);
    size_t pos = 0;
    // The next line without its '\n' (and a '\r' before it); false when no '\n' follows.
    const auto next_line = [&](std::string_view& line) {
        const void* nl = std::memchr(text + pos, '\n', size - pos);
        if (!nl) return false;
        const size_t end = size_t(static_cast<const char*>(nl) - text);
        line = std::string_view(text + pos, end - pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos = end + 1;
        return true;
    };
    const auto unterminated = [&](const char* what) {
        if (size < file_size) return ImageIoError(fmt::format("{}: its header is longer than {} KiB ({})", name, kMaxHeaderBytes >> 10, what));
        return ImageIoError(fmt::format("{}: truncated in its header ({})", name, what));
    };
    if (size < 2 || text[0] != '#' || text[1] != '?')
        throw ImageIoError(fmt::format("{}: not a Radiance HDR file (it must begin with #?RADIANCE)", name));
    std::string_view line;
    if (!next_line(line)) throw unterminated("no end of the first line");
    for (;;) {
        if (!next_line(line)) throw unterminated("no empty line ends it");
        if (line.empty()) break;
        if (line.substr(0, 7) == "FORMAT=") {
            std::string_view format = line.substr(7);
            while (!format.empty() && is_blank(format.back())) format.remove_suffix(1);
            while (!format.empty() && is_blank(format.front())) format.remove_prefix(1);
            if (format != "32-bit_rle_rgbe")
                throw ImageIoError(fmt::format("{}: unsupported pixel format '{}' (only 32-bit_rle_rgbe is read)", name,
                                               std::string(format.substr(0, 64))));
        }
    }
    if (!next_line(line)) throw unterminated("no resolution line");
    std::vector<std::string_view> tokens;
    for (size_t i = 0; i < line.size();) {
        while (i < line.size() && is_blank(line[i])) ++i;
        const size_t start = i;
        while (i < line.size() && !is_blank(line[i])) ++i;
        if (i > start) tokens.emplace_back(line.substr(start, i - start));
    }
    RgbeHeader h;
    const std::string shown(line.substr(0, 64));
    if (tokens.size() != 4 || tokens[0].size() != 2 || tokens[2].size() != 2)
        throw ImageIoError(fmt::format("{}: invalid resolution line '{}' (expected -Y height +X width)", name, shown));
    if (tokens[0] != "-Y" || tokens[2] != "+X")
        throw ImageIoError(fmt::format("{}: unsupported orientation '{}' (only -Y height +X width, top row first, is read)", name, shown));
    if (!parse_dimension(tokens[1], h.height) || !parse_dimension(tokens[3], h.width))
        throw ImageIoError(fmt::format("{}: invalid resolution line '{}' (sizes must be positive numbers)", name, shown));
    h.data_start = pos;
    return h;
}

// Decodes scanlines one after the other, checking every length.
class ScanlineDecoder {
public:
    ScanlineDecoder(const uint8_t* data, size_t size, size_t start, int width, int height, const std::string& name)
        : p_(data), n_(size), pos_(start), w_(width), h_(height), name_(name) {}

    // Decodes scanline y into out (4 bytes per pixel).
    void decode(uint8_t* out, int y) {
        y_ = y;
        if (w_ >= 8 && w_ <= 0x7fff && n_ - pos_ >= 4 && p_[pos_] == 2 && p_[pos_ + 1] == 2 && !(p_[pos_ + 2] & 0x80))
            return decode_run_length(out);
        decode_flat(out);
    }

private:
    template <typename... Args>
    [[noreturn]] void corrupt(fmt::format_string<Args...> what, Args&&... args) const {
        throw ImageIoError(fmt::format("{}: corrupt data in scanline {} of {}: {}", name_, y_ + 1, h_,
                                       fmt::format(what, std::forward<Args>(args)...)));
    }
    void need(size_t k) const {
        if (n_ - pos_ < k)
            throw ImageIoError(fmt::format("{}: truncated: the file ends in scanline {} of {} ({} bytes)", name_, y_ + 1, h_, n_));
    }

    void decode_run_length(uint8_t* out) {
        const int width = p_[pos_ + 2] << 8 | p_[pos_ + 3];
        if (width != w_) corrupt("a run-length scanline of width {} in an image {} wide", width, w_);
        pos_ += 4;
        for (int c = 0; c < 4; ++c) {
            for (int x = 0; x < w_;) {
                need(1);
                const int count = p_[pos_++];
                const int left = w_ - x;
                if (count > 128) {
                    const int run = count - 128;
                    if (run > left) corrupt("a run of {} in component {} overflows the scanline ({} pixels left)", run, c, left);
                    need(1);
                    const uint8_t v = p_[pos_++];
                    for (int i = 0; i < run; ++i) out[size_t(x + i) * 4 + size_t(c)] = v;
                    x += run;
                } else {
                    if (count == 0) corrupt("a run of length 0 in component {}", c);
                    if (count > left) corrupt("{} literal bytes in component {} overflow the scanline ({} pixels left)", count, c, left);
                    need(size_t(count));
                    for (int i = 0; i < count; ++i) out[size_t(x + i) * 4 + size_t(c)] = p_[pos_++];
                    x += count;
                }
            }
        }
    }

    void decode_flat(uint8_t* out) {
        int shift = 0;
        for (int x = 0; x < w_;) {
            need(4);
            const uint8_t* q = p_ + pos_;
            pos_ += 4;
            if (q[0] == 1 && q[1] == 1 && q[2] == 1) {
                // Repeat the previous pixel (q[3] << shift) times.
                if (x == 0) corrupt("a repeat with no pixel before it");
                if (shift > 24) corrupt("too many consecutive repeats");
                const uint64_t run = uint64_t(q[3]) << shift;
                const int left = w_ - x;
                if (run == 0) corrupt("a repeat of length 0");
                if (run > uint64_t(left)) corrupt("a repeat of {} overflows the scanline ({} pixels left)", run, left);
                for (uint64_t i = 0; i < run; ++i) std::memcpy(out + size_t(x + int(i)) * 4, out + size_t(x - 1) * 4, 4);
                x += int(run);
                shift += 8;
            } else {
                std::memcpy(out + size_t(x) * 4, q, 4);
                ++x;
                shift = 0;
            }
        }
    }

    const uint8_t* p_;
    size_t n_, pos_;
    int w_, h_, y_ = 0;
    const std::string& name_;
};

}  // namespace

Image read_rgbe(const ByteSource& src, const ImageReadLimits& limits) {
    const Bytes head(src, kMaxHeaderBytes);
    const RgbeHeader h = parse_header(head.data(), head.size(), src.size(), src.name());
    check_image_size(src.name(), uint64_t(h.width), uint64_t(h.height), limits.max_pixels, sizeof(Rgb));
    // No valid scanline takes more than 4 + 8 W bytes (run-length data at its worst: literal
    // runs of one byte); anything beyond is never read.
    const uint64_t most = h.data_start + uint64_t(h.height) * (4 + 8 * uint64_t(h.width));
    const Bytes all(src, most);
    std::vector<uint8_t> scanline(size_t(h.width) * 4);
    // First every scanline is decoded and checked; only then is the image allocated.
    {
        ScanlineDecoder check(all.data(), all.size(), h.data_start, h.width, h.height, src.name());
        for (int y = 0; y < h.height; ++y) check.decode(scanline.data(), y);
    }
    Image img(h.width, h.height);
    ScanlineDecoder decoder(all.data(), all.size(), h.data_start, h.width, h.height, src.name());
    for (int y = 0; y < h.height; ++y) {
        decoder.decode(scanline.data(), y);
        for (int x = 0; x < h.width; ++x) {
            const uint8_t* q = &scanline[size_t(x) * 4];
            if (q[3] == 0) continue;  // (0, 0, 0)
            const float f = std::ldexp(1.0f, int(q[3]) - 136);
            img.at(x, y) = Rgb(float(q[0]) * f, float(q[1]) * f, float(q[2]) * f);
        }
    }
    return img;
}

}  // namespace pathlab::io
