// libFuzzer target for the checkpoint reader (read_checkpoint): any input must load or fail with
// a CheckpointError; a loaded checkpoint's film must have its header's size. The input's last 8
// bytes are replaced by its checksum first (XXH3 of the rest, as the writer puts it), so that
// the fuzzer reaches what follows the checksum: a forged file with a valid checksum. From a file
// per input. Built and run by scripts/fuzz.sh checkpoint.
#include <unistd.h>
#include <xxhash.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>

#include "job/checkpoint.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/pathlab-fuzz-checkpoint-" + std::to_string(getpid()) + ".ckpt";
    std::string bytes(reinterpret_cast<const char*>(data), size);
    if (bytes.size() >= 8) {
        const uint64_t checksum = XXH3_64bits(bytes.data(), bytes.size() - 8);
        std::memcpy(bytes.data() + bytes.size() - 8, &checksum, 8);
    }
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    try {
        const pathlab::Checkpoint c = pathlab::read_checkpoint(path);
        if (c.film.width() != c.info.width || c.film.height() != c.info.height) __builtin_trap();
    } catch (const pathlab::CheckpointError&) {
    }
    return 0;
}
