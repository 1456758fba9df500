// Mitsuba's .vol grids (format: grid_files.hpp).
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/input_file.hpp"
#include "media/grid_files.hpp"

namespace pathlab {
namespace {

constexpr size_t kHeaderBytes = 48;

int32_t read_i32(std::string_view b, size_t at) {
    const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
    return int32_t(uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24);
}
float read_f32(std::string_view b, size_t at) {
    const uint32_t u = uint32_t(read_i32(b, at));
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}
void put_i32(std::string& out, int32_t v) {
    for (int k = 0; k < 4; ++k) out += char((uint32_t(v) >> (8 * k)) & 0xff);
}
void put_f32(std::string& out, float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    put_i32(out, int32_t(u));
}

}  // namespace

VoxelGrid parse_vol(std::string_view bytes, const std::string& name) {
    const auto fail = [&](const std::string& why) -> GridFileError {
        return GridFileError(fmt::format("grid file '{}': {}", name, why));
    };
    if (bytes.size() < 4 || bytes.substr(0, 3) != "VOL")
        throw fail("not a Mitsuba .vol grid (it must begin with the bytes 'VOL')");
    if (bytes[3] != 3) throw fail(fmt::format("unsupported .vol version {} (pathlab reads version 3)", int(bytes[3])));
    if (bytes.size() < kHeaderBytes)
        throw fail(fmt::format("truncated: the header needs {} bytes, the file has {}", kHeaderBytes, bytes.size()));
    const int32_t encoding = read_i32(bytes, 4);
    if (encoding != 1) throw fail(fmt::format("unsupported encoding {} (pathlab reads 1, float32, as Mitsuba 3 does)", encoding));
    VoxelGrid g;
    for (int a = 0; a < 3; ++a) g.res[size_t(a)] = read_i32(bytes, 8 + 4 * size_t(a));
    g.channels = read_i32(bytes, 20);
    if (g.res[0] <= 0 || g.res[1] <= 0 || g.res[2] <= 0)
        throw fail(fmt::format("invalid dimensions {}x{}x{} (each must be positive)", g.res[0], g.res[1], g.res[2]));
    if (g.channels != 1 && g.channels != 3) throw fail(fmt::format("unsupported channel count {} (1 or 3)", g.channels));
    // 64-bit products: each factor is below 2^31, so three of them and the channels cannot wrap.
    const unsigned __int128 values = (unsigned __int128)uint64_t(g.res[0]) * uint64_t(g.res[1]) * uint64_t(g.res[2]) * uint64_t(g.channels);
    const size_t data_bytes = bytes.size() - kHeaderBytes;
    if (values * 4 > data_bytes) {
        const std::string need = values < (unsigned __int128)1 << 60 ? fmt::format("{}", uint64_t(values) * 4) : "more than 2^62";
        throw fail(fmt::format("truncated: {}x{}x{} voxels of {} channel(s) need {} bytes of data, the file has {}", g.res[0],
                               g.res[1], g.res[2], g.channels, need, data_bytes));
    }
    if (values * 4 < data_bytes)
        throw fail(fmt::format("{} bytes after the data of {}x{}x{} voxels of {} channel(s): wrong dimensions?",
                               data_bytes - size_t(values) * 4, g.res[0], g.res[1], g.res[2], g.channels));
    if (values > kMaxGridValues) throw fail(fmt::format("{} values is more than pathlab loads ({})", uint64_t(values), kMaxGridValues));
    g.data.resize(size_t(values));
    for (size_t i = 0; i < g.data.size(); ++i) {
        const float v = read_f32(bytes, kHeaderBytes + 4 * i);
        if (!std::isfinite(v) || v < 0) {
            const size_t voxel = i / size_t(g.channels);
            const size_t x = voxel % size_t(g.res[0]), y = voxel / size_t(g.res[0]) % size_t(g.res[1]),
                         z = voxel / (size_t(g.res[0]) * size_t(g.res[1]));
            throw fail(fmt::format("voxel ({}, {}, {}) channel {} is {}: grid values must be finite and not negative", x, y, z,
                                   i % size_t(g.channels), v));
        }
        g.data[i] = v;
    }
    return g;
}

void require_regular_grid_file(const std::string& path) {
    try {
        require_input_file(path);
    } catch (const InputFileError& e) {
        throw GridFileError(fmt::format("grid file '{}': {}", path, e.what()));
    }
}

VoxelGrid read_vol_file(const std::string& path) {
    // The header alone bounds what the data may take: refuse before reading a huge file.
    std::string bytes;
    try {
        bytes = read_input_file(path, kHeaderBytes + 4 * kMaxGridValues);
    } catch (const InputFileError& e) {
        throw GridFileError(fmt::format("grid file '{}': {}", path, e.what()));
    }
    return parse_vol(bytes, path);
}

void write_vol_file(const std::string& path, const VoxelGrid& g) {
    std::string out = "VOL";
    out += char(3);
    put_i32(out, 1);
    for (int a = 0; a < 3; ++a) put_i32(out, g.res[size_t(a)]);
    put_i32(out, g.channels);
    for (float b : {0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f}) put_f32(out, b);
    for (float v : g.data) put_f32(out, v);
    const std::string tmp = path + ".tmp";
    {
        std::ofstream f(tmp, std::ios::binary);
        f.write(out.data(), std::streamsize(out.size()));
        if (!f.flush()) throw GridFileError(fmt::format("grid file '{}': cannot write it", path));
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw GridFileError(fmt::format("grid file '{}': cannot write it: {}", path, ec.message()));
}

}  // namespace pathlab
