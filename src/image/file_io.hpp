// The file plumbing under the image readers and writers (internal to src/image):
//  - ByteSource: the bytes of a file or of a buffer in memory, read at offsets with every
//    short read reported; files must be regular files (no devices, FIFOs, directories);
//  - FdWriter: buffered writes to a file descriptor, every write, seek and flush checked;
//  - write_file_atomically: temporary file, checked writes, fsync, close, rename.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/input_file.hpp"

namespace pathlab::io {

class ByteSource {
public:
    virtual ~ByteSource() = default;
    uint64_t size() const { return size_; }
    const std::string& name() const { return name_; }
    // Copies n bytes at `offset` to dst; throws ImageIoError naming the file when fewer exist.
    virtual void read(uint64_t offset, void* dst, size_t n) const = 0;
    // All bytes, when they are in memory already; nullptr otherwise.
    virtual const uint8_t* data() const { return nullptr; }

protected:
    ByteSource(std::string name, uint64_t size) : name_(std::move(name)), size_(size) {}
    [[noreturn]] void throw_truncated(uint64_t offset, size_t n) const;

private:
    std::string name_;
    uint64_t size_;
};

class MemorySource final : public ByteSource {
public:
    MemorySource(const void* data, size_t size, std::string name);
    void read(uint64_t offset, void* dst, size_t n) const override;
    const uint8_t* data() const override { return data_; }

private:
    const uint8_t* data_;
};

// Opens `path` for reading; throws ImageIoError for a missing or unreadable file and for
// anything that is not a regular file (it is opened without blocking, so a FIFO does not hang).
class FileSource final : public ByteSource {
public:
    explicit FileSource(const std::string& path);
    void read(uint64_t offset, void* dst, size_t n) const override;

private:
    FileSource(const std::string& path, std::unique_ptr<InputFile> file);
    std::unique_ptr<InputFile> file_;
};

// The first min(size, max_bytes) bytes of a source, in memory (without a copy for a MemorySource).
class Bytes {
public:
    Bytes(const ByteSource& src, uint64_t max_bytes);
    const uint8_t* data() const { return data_; }
    size_t size() const { return size_; }

private:
    std::vector<uint8_t> storage_;
    const uint8_t* data_;
    size_t size_;
};

// Buffered writes to an open file descriptor (not closed by the writer). The first failure is
// kept: write(), seek() and flush() throw ImageIoError with "name: cannot write: reason", and
// put() (for C callbacks, which must not throw) records it and ignores what follows.
class FdWriter {
public:
    FdWriter(int fd, std::string name);
    void write(const void* data, size_t n);
    void put(const void* data, size_t n) noexcept;
    uint64_t position() const { return buffer_start_ + buffer_.size(); }
    void seek(uint64_t position);
    void flush();                  // writes out the buffer; throws any failure seen so far
    void fail(const std::string& reason);  // records a failure (if none yet) and throws it
    bool failed() const { return !error_.empty(); }
    [[noreturn]] void throw_error() const;

private:
    void write_out(const char* data, size_t n);
    int fd_;
    std::string name_, error_;
    std::vector<char> buffer_;
    uint64_t buffer_start_ = 0;
};

// Writes `path` through a new temporary file next to it: runs write(writer), flushes, fsyncs
// and closes the file, checking each, then renames it onto `path`. On any failure the temporary
// is removed, `path` is left as it was, and ImageIoError says why. Before writing, removes
// temporaries of `path` whose process no longer exists.
void write_file_atomically(const std::string& path, const std::function<void(FdWriter&)>& write);

// Creates a temporary file for `path` and removes it again (a check that `path` can be written).
void probe_writable(const std::string& path);

// ".NAME.pathlab-tmp-": the prefix of every temporary of `path` (NAME possibly shortened so
// that the temporary's name stays within the file system's limit).
std::string temporary_prefix(const std::string& path);

// Removes the temporaries of `path` left by processes that no longer exist.
void remove_stale_temporaries(const std::string& path);

// Throws ImageIoError when a width x height image is larger than `max_pixels` allows, saying
// how much memory it would need at `bytes_per_pixel`.
void check_image_size(const std::string& name, uint64_t width, uint64_t height, uint64_t max_pixels, unsigned bytes_per_pixel);

}  // namespace pathlab::io
