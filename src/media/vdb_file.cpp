// .vdb files through the OpenVDB module (openvdb_module.cpp, libpathlab_openvdb.so), loaded on
// first use: from $PATHLAB_OPENVDB_MODULE, else next to the running program, else where the
// build put it.
#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include <fmt/format.h>

#include "media/grid_files.hpp"

#ifndef PATHLAB_OPENVDB_MODULE
#define PATHLAB_OPENVDB_MODULE ""
#endif

namespace pathlab {
namespace {

using ReadFn = bool (*)(const std::string*, const std::string*, VdbGrid*, std::string*);
using WriteFn = bool (*)(const std::string*, const VoxelGrid*, const std::string*, double, std::string*);

struct OpenVdbModule {
    ReadFn read = nullptr;
    WriteFn write = nullptr;
    std::string error;  // why it could not be loaded
};

const OpenVdbModule& openvdb_module() {
    static const OpenVdbModule module = [] {
        OpenVdbModule m;
        std::vector<std::string> candidates;
        if (const char* env = std::getenv("PATHLAB_OPENVDB_MODULE"); env && *env) candidates.push_back(env);
        char exe[PATH_MAX];
        if (const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1); n > 0)
            candidates.push_back((std::filesystem::path(std::string(exe, size_t(n))).parent_path() / "libpathlab_openvdb.so").string());
        if (*PATHLAB_OPENVDB_MODULE) candidates.push_back(PATHLAB_OPENVDB_MODULE);
        std::vector<std::string> tried;
        for (const std::string& file : candidates) {
            std::error_code ec;
            if (!std::filesystem::exists(file, ec)) {
                tried.push_back(file + " (missing)");
                continue;
            }
            void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (!handle) {
                const char* why = dlerror();
                tried.push_back(fmt::format("{} ({})", file, why ? why : "dlopen failed"));
                continue;
            }
            m.read = reinterpret_cast<ReadFn>(dlsym(handle, "pathlab_openvdb_read"));
            m.write = reinterpret_cast<WriteFn>(dlsym(handle, "pathlab_openvdb_write"));
            if (m.read && m.write) return m;
            tried.push_back(file + " (not pathlab's OpenVDB module)");
        }
        m.read = nullptr, m.write = nullptr;
        m.error = fmt::format("pathlab's OpenVDB module libpathlab_openvdb.so was not found: tried {}",
                              tried.empty() ? "nothing" : fmt::format("{}", fmt::join(tried, ", ")));
        return m;
    }();
    return module;
}


// Text read from a file, for a message: a corrupted file's names hold any bytes (control
// characters shown as \xNN).
std::string escaped(const std::string& text) {
    std::string shown;
    for (const unsigned char c : text) shown += (c >= 0x20 && c != 0x7f) ? std::string(1, char(c)) : fmt::format("\\x{:02x}", c);
    return shown;
}

// The size OpenVDB reads for a grid metadata value of a fixed-size type, whatever size the file
// gives (0: any size: strings, types it does not know). A file whose size disagrees would put
// OpenVDB's reading out of step with the file, reading lengths from the middle of values.
uint32_t fixed_metadata_size(const std::string& type) {
    static const std::vector<std::pair<std::string, uint32_t>> sizes = {
        {"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},  {"double", 8}, {"vec2i", 8},  {"vec2s", 8},
        {"vec2d", 16}, {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16}, {"vec4s", 16}, {"vec4d", 32},
        {"mat4s", 64}, {"mat4d", 128}};
    for (const auto& [name, size] : sizes)
        if (name == type) return size;
    return 0;
}

// The layout of a .vdb file, checked before OpenVDB reads it (OpenVDB trusts it: a grid offset
// that points backwards made it loop forever, a file cut short inside its header too, a flipped
// metadata count or string length made it allocate gigabytes): the header (magic, file format 219
// to 224 with grid offsets, the UUID), the file's metadata, and for every grid its descriptor, its
// span (starting right after the descriptor, as OpenVDB writes it and its stream reader reads it;
// data block and end after it, within the file), and the start of its data: the compression
// flags and every metadata entry (each string and value within the grid's header, fixed-size
// values of their size, the delayed-load table's counts within the file). What follows (the
// transform, the tree) OpenVDB reads from a stream that throws at the end of the file, so no
// count read from it runs on past the file's bytes. The layout is OpenVDB's (io/Archive.cc,
// io/GridDescriptor.cc, Metadata.h, io/DelayedLoadMetadata.cc), file format 219 (OpenVDB 2.0) on.
void check_vdb_layout(const std::string& path) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) return;  // the module says why it cannot read it
    std::ifstream in(path, std::ios::binary);
    if (!in) return;
    uint64_t at = 0, limit = size;  // limit: the end of the part being read (the file, a grid's header)
    const auto fail = [&](const std::string& why) {
        return GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: {} (at byte {} of {})", path, why, at, size));
    };
    const auto bytes = [&](void* out, uint64_t n, const std::string& what) {
        if (n > limit - at) throw fail(fmt::format("it ends inside its {}", what));
        in.seekg(std::streamoff(at));
        in.read(static_cast<char*>(out), std::streamsize(n));
        if (!in) throw fail(fmt::format("its {} cannot be read", what));
        at += n;
    };
    const auto u32 = [&](const std::string& what) {
        uint32_t v;
        bytes(&v, 4, what);
        return v;
    };
    const auto i64 = [&](const char* what) {
        int64_t v;
        bytes(&v, 8, what);
        return v;
    };
    const auto skip = [&](uint64_t n, const std::string& what) {
        if (n > limit - at) throw fail(fmt::format("its {} claims {} bytes, more than {} left", what, n, limit == size ? "the file has" : "its grid header has"));
        at += n;
    };
    const auto skip_string = [&](const std::string& what) { skip(u32(what), what); };
    const auto string = [&](const std::string& what) {
        const uint32_t n = u32(what);
        if (n > 4096) throw fail(fmt::format("its {} claims {} bytes", what, n));
        std::string s(n, '\0');
        bytes(s.data(), n, what);
        return s;
    };
    int64_t magic = i64("magic number");
    if (magic != 0x56444220) throw fail("no OpenVDB magic number");
    const uint32_t version = u32("file format version");
    if (version < 219 || version > 224)
        throw fail(fmt::format("file format version {}; pathlab reads 219 (OpenVDB 2) to 224", version));
    u32("library version"), u32("library version");
    char offsets = 0;
    bytes(&offsets, 1, "header");
    if (offsets != 1) throw fail("its grids have no offsets (an OpenVDB 1 stream, not a file)");
    char uuid[36];
    bytes(uuid, 36, "UUID");
    const uint32_t metadata = u32("metadata count");
    if (metadata > size - at) throw fail(fmt::format("it claims {} metadata entries", metadata));
    for (uint32_t i = 0; i < metadata; ++i) skip_string("metadata name"), skip_string("metadata type"), skip_string("metadata value");
    const uint32_t grids = u32("grid count");
    if (grids > size - at) throw fail(fmt::format("it claims {} grids", grids));
    for (uint32_t g = 0; g < grids; ++g) {
        skip_string("grid name"), skip_string("grid type"), skip_string("grid instance's parent name");
        const int64_t grid = i64("grid position"), block = i64("grid position"), end = i64("grid position");
        if (!(int64_t(at) == grid && grid <= block && block <= end && uint64_t(end) <= size))
            throw fail(fmt::format("grid {} spans bytes {} (its data {}) to {}, not within its part of the file", g + 1, grid, block, end));
        limit = uint64_t(block);
        if (version >= 222) u32("grid compression flags");
        const uint32_t entries = u32("grid metadata count");
        if (entries > limit - at) throw fail(fmt::format("grid {} claims {} metadata entries", g + 1, entries));
        for (uint32_t i = 0; i < entries; ++i) {
            const std::string name = escaped(string("grid metadata name")), type = string(fmt::format("grid metadata '{}''s type", name));
            const std::string what = fmt::format("grid metadata '{}' ({})", name, escaped(type));
            const uint32_t n = u32(what + "'s size");
            const uint64_t value = at;
            skip(n, what);
            if (const uint32_t fixed = fixed_metadata_size(type); fixed != 0 && n != fixed)
                throw fail(fmt::format("its {} has {} bytes, not {}", what, n, fixed));
            if (type != "__delayedload" || n == 0) continue;
            // The delayed-load table: a count (one entry per leaf node, each more than a byte of
            // the file), then a mask byte and a compressed size (8 bytes) per entry, each table
            // raw or blosc-compressed (its header's bytes 4-7: the uncompressed size).
            const uint64_t value_end = at;
            limit = value_end, at = value;
            const uint32_t count = u32(what + "'s count");
            if (count > size) throw fail(fmt::format("its {} claims {} leaf nodes", what, count));
            for (const uint64_t entry : {uint64_t(1), uint64_t(8)}) {
                const uint32_t packed = u32(what + "'s table size");
                if (entry == 8 && packed == UINT32_MAX) break;  // no compressed sizes
                if (packed == 0) {
                    skip(count * entry, what + "'s table");
                    continue;
                }
                const uint64_t table = at;
                uint32_t unpacked = 0;
                skip(4, what + "'s blosc header"), bytes(&unpacked, 4, what + "'s blosc header");
                if (unpacked != count * entry)
                    throw fail(fmt::format("its {} has a table of {} bytes for {} entries", what, unpacked, count));
                at = table;
                skip(packed, what + "'s table");
            }
            at = value_end, limit = uint64_t(block);
        }
        limit = size;
        at = uint64_t(end);
    }
}

}  // namespace

VdbGrid read_vdb_file(const std::string& path, const std::string& grid_name) {
    const OpenVdbModule& m = openvdb_module();
    if (!m.read) throw GridFileError(fmt::format("grid file '{}': {}", path, m.error));
    require_regular_grid_file(path);  // before the layout check opens it (a named pipe: a hang)
    check_vdb_layout(path);
    VdbGrid out;
    std::string error;
    if (!m.read(&path, &grid_name, &out, &error)) throw GridFileError(escaped(error));
    return out;
}

void write_vdb_file(const std::string& path, const VoxelGrid& grid, const std::string& grid_name, double voxel_size) {
    const OpenVdbModule& m = openvdb_module();
    if (!m.write) throw GridFileError(fmt::format("grid file '{}': {}", path, m.error));
    std::string error;
    if (!m.write(&path, &grid, &grid_name, voxel_size, &error)) throw GridFileError(error);
}

}  // namespace pathlab
