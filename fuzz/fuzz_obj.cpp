// libFuzzer target for the OBJ mesh loader (load_obj_mesh): any input must load or fail with a
// MeshLoadError; a loaded mesh must be usable (every index inside the vertex list, one normal
// per vertex or none, finite positions). The loader reads files, so each input is written to a
// file in /dev/shm (or $TMPDIR) first. Built and run by scripts/fuzz.sh obj.
//
// tinyobjloader's implementation is compiled into this target (instrumented, and preferred by
// the linker to the same version's shared library), so that the fuzzer sees its coverage too.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "fuzz_mesh_checks.hpp"
#include "geometry/shape_meshes.hpp"

namespace {

std::string input_path() {
    const char* tmp = std::getenv("TMPDIR");
    const std::string dir = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : tmp ? tmp : "/tmp";
    return dir + "/pathlab-fuzz-obj-" + std::to_string(getpid()) + ".obj";
}

}  // namespace

const std::string& input_file() {
    static const std::string path = [] {
        std::atexit([] { std::remove(input_path().c_str()); });  // libFuzzer ends with exit()
        return input_path();
    }();
    return path;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string& path = input_file();
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    try {
        const pathlab::MeshDesc m = pathlab::load_obj_mesh(path);
        if (!m.normals.empty() && m.normals.size() != m.positions.size()) __builtin_trap();
        check_usable_mesh(m);
    } catch (const pathlab::MeshLoadError&) {
    }
    return 0;
}
