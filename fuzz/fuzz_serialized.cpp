// libFuzzer target for Mitsuba's .serialized mesh reader (load_serialized_mesh, zlib-compressed
// shapes with a table of offsets at the end): any input must load or fail with a MeshLoadError;
// a loaded mesh must be usable (indices within its vertices, finite positions). From a file per
// input (the reader takes a path). Built and run by scripts/fuzz.sh serialized.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "fuzz_mesh_checks.hpp"
#include "geometry/mesh_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/pathlab-fuzz-serialized-" + std::to_string(getpid()) + ".serialized";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    for (const int shape : {0, 1}) {
        try {
            const pathlab::MeshDesc m = pathlab::load_serialized_mesh(path, shape);
            check_usable_mesh(m);
        } catch (const pathlab::MeshLoadError&) {
        }
    }
    return 0;
}
