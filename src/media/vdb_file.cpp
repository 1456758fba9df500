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


// The layout of a .vdb file, checked before OpenVDB reads it (OpenVDB trusts it: a grid offset
// that points backwards made it loop forever, a file cut short inside its header too): the header
// (magic, file format 219 to 224 with grid offsets, the UUID), the file's metadata and every grid
// descriptor, each string and record within the file, and each grid's span (grid, block and end
// positions) increasing, after its descriptor and within the file. File format 219 (OpenVDB 2.0)
// on: the layout below is theirs (io/Archive.cc, io/GridDescriptor.cc).
void check_vdb_layout(const std::string& path) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    std::ifstream in(path, std::ios::binary);
    if (ec || !in) return;  // the module says why it cannot read it
    uint64_t at = 0;
    const auto fail = [&](const std::string& why) {
        return GridFileError(fmt::format("grid file '{}': not a readable OpenVDB file: {} (at byte {} of {})", path, why, at, size));
    };
    const auto bytes = [&](void* out, uint64_t n, const char* what) {
        if (n > size - at) throw fail(fmt::format("it ends inside its {}", what));
        in.seekg(std::streamoff(at));
        in.read(static_cast<char*>(out), std::streamsize(n));
        if (!in) throw fail(fmt::format("its {} cannot be read", what));
        at += n;
    };
    const auto u32 = [&](const char* what) {
        uint32_t v;
        bytes(&v, 4, what);
        return v;
    };
    const auto i64 = [&](const char* what) {
        int64_t v;
        bytes(&v, 8, what);
        return v;
    };
    const auto skip_string = [&](const char* what) {
        const uint32_t n = u32(what);
        if (n > size - at) throw fail(fmt::format("its {} claims {} bytes, more than the file has left", what, n));
        at += n;
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
        if (!(int64_t(at) <= grid && grid <= block && block <= end && uint64_t(end) <= size))
            throw fail(fmt::format("grid {} spans bytes {} (its data {}) to {}, not within its part of the file", g + 1, grid, block, end));
        at = uint64_t(end);
    }
}

}  // namespace

VdbGrid read_vdb_file(const std::string& path, const std::string& grid_name) {
    const OpenVdbModule& m = openvdb_module();
    if (!m.read) throw GridFileError(fmt::format("grid file '{}': {}", path, m.error));
    check_vdb_layout(path);
    VdbGrid out;
    std::string error;
    if (!m.read(&path, &grid_name, &out, &error)) throw GridFileError(error);
    return out;
}

void write_vdb_file(const std::string& path, const VoxelGrid& grid, const std::string& grid_name, double voxel_size) {
    const OpenVdbModule& m = openvdb_module();
    if (!m.write) throw GridFileError(fmt::format("grid file '{}': {}", path, m.error));
    std::string error;
    if (!m.write(&path, &grid, &grid_name, voxel_size, &error)) throw GridFileError(error);
}

}  // namespace pathlab
