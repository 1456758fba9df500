// .vdb files through the OpenVDB module (openvdb_module.cpp, libpathlab_openvdb.so), loaded on
// first use: from $PATHLAB_OPENVDB_MODULE, else next to the running program, else where the
// build put it.
#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <filesystem>
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

}  // namespace

VdbGrid read_vdb_file(const std::string& path, const std::string& grid_name) {
    const OpenVdbModule& m = openvdb_module();
    if (!m.read) throw GridFileError(fmt::format("grid file '{}': {}", path, m.error));
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
