// libFuzzer target for the PLY mesh reader (load_ply_mesh: pathlab's walk of the header and body,
// then Assimp): any input must load or fail with a MeshLoadError; a loaded mesh must be usable
// (indices within its vertices, finite positions). Assimp reads files: each input is written to a
// file of this process first. Built and run by scripts/fuzz.sh ply.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "fuzz_mesh_checks.hpp"
#include "geometry/mesh_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/pathlab-fuzz-ply-" + std::to_string(getpid()) + ".ply";
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    try {
        const pathlab::MeshDesc m = pathlab::load_ply_mesh(path);
        check_usable_mesh(m);
    } catch (const pathlab::MeshLoadError&) {
    }
    return 0;
}
