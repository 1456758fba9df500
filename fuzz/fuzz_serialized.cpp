// libFuzzer target for Mitsuba's .serialized mesh reader (load_serialized_mesh, zlib-compressed
// shapes with a table of offsets at the end): any input must load or fail with a MeshLoadError;
// a loaded mesh must be usable (indices within its vertices, finite positions). From a file per
// input (the reader takes a path). Built and run by scripts/fuzz.sh serialized.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "geometry/mesh_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/pathlab-fuzz-serialized-" + std::to_string(getpid()) + ".serialized";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    for (const int shape : {0, 1}) {
        try {
            const pathlab::MeshDesc m = pathlab::load_serialized_mesh(path, shape);
            for (const auto& t : m.triangles)
                for (const uint32_t i : t)
                    if (i >= m.positions.size()) __builtin_trap();
            for (const pathlab::Vec3f& p : m.positions)
                if (!pathlab::is_finite(p)) __builtin_trap();
        } catch (const pathlab::MeshLoadError&) {
        }
    }
    return 0;
}
