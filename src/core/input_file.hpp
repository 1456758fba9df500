// Opening the files pathlab reads (scene files and their includes, spectra, grids, meshes, IES
// profiles, images, reference mappings and manifests): opened without blocking (opening a FIFO
// waits for a writer) and refused unless the opened file is a regular one (a device such as
// /dev/zero never ends), checked on the descriptor itself, so that nothing can replace the file
// between the check and the reading. Every reader names the file in its own error type; an
// InputFileError's what() is the problem alone ("no such file", "is a directory", ...).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace pathlab {

struct InputFileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// An open regular file, closed with the object.
class InputFile {
public:
    explicit InputFile(const std::string& path);
    ~InputFile();
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;

    int fd() const { return fd_; }
    uint64_t size() const { return size_; }
    // The whole file; an InputFileError if it has more than `max_bytes` bytes ("a file of N
    // bytes; at most M are read") or cannot be read.
    std::string read_all(uint64_t max_bytes) const;

private:
    int fd_;
    uint64_t size_;
};

// The whole file at `path` (see InputFile::read_all).
std::string read_input_file(const std::string& path, uint64_t max_bytes);
// Checks that `path` opens as a regular file, for readers that give the path to a library.
void require_input_file(const std::string& path);

}  // namespace pathlab
