// libFuzzer target for the .vdb reader (read_vdb_file: vdb_file.cpp's layout checks, then OpenVDB
// through pathlab's module): any input must load or fail with a GridFileError; a loaded grid must
// be usable (its size matching its dimensions, every value finite and not negative). OpenVDB reads
// files, not memory: each input is written to a file of this process first. OpenVDB is Debian's
// (not instrumented): the fuzzer steers by pathlab's checks and catches crashes, hangs and
// allocations over the limit inside OpenVDB. Built and run by scripts/fuzz.sh vdb.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "media/grid_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/pathlab-fuzz-vdb-" + std::to_string(getpid()) + ".vdb";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    try {
        const pathlab::VdbGrid v = pathlab::read_vdb_file(path);
        const pathlab::VoxelGrid& g = v.grid;
        if (g.data.size() != g.voxel_count() * size_t(g.channels)) __builtin_trap();
        for (float x : g.data)
            if (!std::isfinite(x) || x < 0) __builtin_trap();
    } catch (const pathlab::GridFileError&) {
    }
    return 0;
}
