#include "job/checkpoint.hpp"

#include <unistd.h>
#include <xxhash.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <cstring>
#include <sstream>

#include <fmt/format.h>

#include "core/input_file.hpp"
#include "image/file_io.hpp"
#include "image/image_io.hpp"

namespace pathlab {
namespace {

constexpr uint32_t kMaxHeader = 1u << 20;
constexpr size_t kChunkPixels = size_t(1) << 14;  // 2.5 MiB per write

std::string header_text(const CheckpointInfo& info) {
    return info.identity.to_text() + fmt::format("passes={}\nwidth={}\nheight={}\nseconds={}\npathlab={}\n", info.passes.to_string(),
                                                 info.width, info.height, info.seconds, info.writer) +
           (info.command.empty() ? "" : "command=" + info.command + "\n");
}

uint32_t le32(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }
uint64_t le64(const uint8_t* p) { return uint64_t(le32(p)) | uint64_t(le32(p + 4)) << 32; }

class Reader {
public:
    explicit Reader(const std::string& path) try : src_(path), path_(path) {
    } catch (const ImageIoError& e) {
        throw CheckpointError(fmt::format("{}: cannot read the checkpoint ({})", path, e.what()));
    }
    uint64_t size() const { return src_.size(); }
    void read(uint64_t offset, void* dst, size_t n) {
        try {
            src_.read(offset, dst, n);
        } catch (const ImageIoError& e) {
            throw CheckpointError(fmt::format("{}: cannot read the checkpoint ({})", path_, e.what()));
        }
    }
    // The header: info and where the pixels start.
    CheckpointInfo header(uint64_t& pixels_at) {
        const auto bad = [&](const std::string& why) { return CheckpointError(fmt::format("{}: {}", path_, why)); };
        if (size() < 16) throw bad(fmt::format("not a pathlab checkpoint (it is only {} bytes long)", size()));
        uint8_t head[16];
        read(0, head, 16);
        if (std::memcmp(head, kCheckpointMagic, 8) != 0) throw bad("not a pathlab checkpoint (no PLCKPT magic)");
        const uint32_t version = le32(head + 8), h = le32(head + 12);
        if (version != kCheckpointVersion)
            throw bad(fmt::format("a checkpoint of format version {}, this pathlab reads version {}", version, kCheckpointVersion));
        if (h > kMaxHeader) throw bad(fmt::format("corrupted: a header of {} bytes", h));
        if (size() < 16 + uint64_t(h) + 16) throw bad(fmt::format("truncated: {} bytes, too short for its header", size()));
        std::string text(h, '\0');
        read(16, text.data(), h);
        uint8_t count_bytes[8];
        read(16 + h, count_bytes, 8);
        const uint64_t pixels = le64(count_bytes);
        CheckpointInfo info;
        std::istringstream in(text);
        std::string line, passes;
        bool have_passes = false;
        while (std::getline(in, line)) {
            const size_t eq = line.find('=');
            if (eq == std::string::npos) throw bad("corrupted: a header line without '='");
            const std::string key = line.substr(0, eq), value = line.substr(eq + 1);
            try {
                if (key == "passes") passes = value, have_passes = true;
                else if (key == "width") info.width = std::stoi(value);
                else if (key == "height") info.height = std::stoi(value);
                else if (key == "seconds") info.seconds = std::stod(value);
                else if (key == "pathlab") info.writer = value;
                else if (key == "command") info.command = value;
                else info.identity.fields.emplace_back(key, value);
            } catch (const std::exception&) {
                throw bad(fmt::format("corrupted: header line '{}'", line));
            }
        }
        if (!(info.seconds >= 0) || !std::isfinite(info.seconds)) throw bad(fmt::format("corrupted: {} seconds of rendering", info.seconds));
        const std::optional<PassSet> set = PassSet::parse(passes);
        if (!have_passes || !set) throw bad("corrupted: no valid list of passes in its header");
        info.passes = *set;
        if (info.width <= 0 || info.height <= 0 || uint64_t(info.width) * uint64_t(info.height) != pixels)
            throw bad(fmt::format("corrupted: {} pixels for a {}x{} image", pixels, info.width, info.height));
        pixels_at = 16 + uint64_t(h) + 8;
        // Checked before anything is allocated: the size a complete file of this image has.
        if (pixels > (uint64_t(1) << 36) / sizeof(PixelSums)) throw bad(fmt::format("corrupted: {} pixels", pixels));
        const uint64_t expected = pixels_at + pixels * sizeof(PixelSums) + 8;
        if (size() != expected)
            throw bad(fmt::format("{}: {} bytes where a complete checkpoint of {}x{} pixels has {}; it cannot be used",
                                  size() < expected ? "truncated" : "corrupted (trailing bytes)", size(), info.width, info.height,
                                  expected));
        return info;
    }

private:
    io::FileSource src_;
    std::string path_;
};

}  // namespace

void write_checkpoint(const std::string& path, RankGroup& parts, const Film& film, const CheckpointInfo& info) {
    if (!parts.root()) {
        parts.reduce_film(film, kChunkPixels, [](size_t, const PixelSums*, size_t) {});
        return;
    }
    const std::string header = header_text(info);
    io::write_file_atomically(path, [&](io::FdWriter& w) {
        XXH3_state_t* state = XXH3_createState();
        XXH3_64bits_reset(state);
        // put() records a failure and goes on quietly: the other ranks are still sending.
        const auto out = [&](const void* p, size_t n) {
            XXH3_64bits_update(state, p, n);
            w.put(p, n);
        };
        const uint32_t fields[2] = {kCheckpointVersion, uint32_t(header.size())};
        const uint64_t pixels = film.pixel_count();
        out(kCheckpointMagic, 8);
        out(fields, sizeof fields);
        out(header.data(), header.size());
        out(&pixels, sizeof pixels);
        parts.reduce_film(film, kChunkPixels, [&](size_t, const PixelSums* sums, size_t n) { out(sums, n * sizeof(PixelSums)); });
        const uint64_t checksum = XXH3_64bits_digest(state);
        XXH3_freeState(state);
        w.put(&checksum, sizeof checksum);
        w.flush();
    });
}

CheckpointInfo read_checkpoint_info(const std::string& path) {
    Reader r(path);
    uint64_t pixels_at = 0;
    return r.header(pixels_at);
}

Checkpoint read_checkpoint(const std::string& path) {
    Reader r(path);
    uint64_t pixels_at = 0;
    Checkpoint c{r.header(pixels_at), {}};
    c.film = Film(c.info.width, c.info.height);
    XXH3_state_t* state = XXH3_createState();
    XXH3_64bits_reset(state);
    std::vector<uint8_t> head(pixels_at);
    r.read(0, head.data(), head.size());
    XXH3_64bits_update(state, head.data(), head.size());
    const size_t n = c.film.pixel_count();
    for (size_t first = 0; first < n; first += kChunkPixels) {
        const size_t k = std::min(kChunkPixels, n - first);
        r.read(pixels_at + first * sizeof(PixelSums), c.film.data() + first, k * sizeof(PixelSums));
        XXH3_64bits_update(state, c.film.data() + first, k * sizeof(PixelSums));
    }
    const uint64_t computed = XXH3_64bits_digest(state);
    XXH3_freeState(state);
    uint8_t stored[8];
    r.read(pixels_at + n * sizeof(PixelSums), stored, 8);
    if (le64(stored) != computed)
        throw CheckpointError(fmt::format("{}: corrupted: its checksum is {:016x} but its content sums to {:016x}; it cannot be used",
                                          path, le64(stored), computed));
    // A checksum passes by chance once in 2^64: still check what the film's use depends on.
    // And sums no render could have made (a forged file with a valid checksum): a pixel takes at
    // most one sample per pass, and per channel its sum of squares is at least sum^2 / count
    // (Cauchy-Schwarz), all finite.
    const uint64_t passes = c.info.passes.count();
    for (size_t i = 0; i < n; ++i) {
        const PixelSums& p = c.film.data()[i];
        const auto invalid = [&](const std::string& why) {
            return CheckpointError(fmt::format("{}: corrupted: pixel {} is invalid: {}; it cannot be used", path, i, why));
        };
        for (int k = 0; k < 6; ++k)
            if (p.top[k] > 80) throw invalid("its sums are out of range");
        if (p.count > passes) throw invalid(fmt::format("{} samples in {} passes", p.count, passes));
        for (int ch = 0; ch < 3; ++ch) {
            const double sum = exact::value(p.sum[ch], p.top[ch]), sumsq = exact::value(p.sumsq[ch], p.top[3 + ch]);
            if (!std::isfinite(sum) || !std::isfinite(sumsq) || sumsq < 0) throw invalid("a sum that is not finite, or a negative sum of squares");
            if (p.count == 0 ? (sum != 0 || sumsq != 0) : sumsq * double(p.count) < sum * sum * (1 - 1e-9))
                throw invalid(fmt::format("channel {}: sum {} and sum of squares {} of {} samples", ch, sum, sumsq, p.count));
        }
    }
    return c;
}

bool is_checkpoint_file(const std::string& path) {
    try {
        const InputFile file(path);
        char magic[sizeof kCheckpointMagic] = {};
        return ::pread(file.fd(), magic, sizeof magic, 0) == ssize_t(sizeof magic) && std::memcmp(magic, kCheckpointMagic, sizeof magic) == 0;
    } catch (const InputFileError&) {
        return false;
    }
}

}  // namespace pathlab
