#include "core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

namespace pathlab {

InputFile::InputFile(const std::string& path) {
    // O_NONBLOCK: opening a FIFO would otherwise wait for a writer.
    fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
        const int e = errno;
        throw InputFileError(e == ENOENT ? std::string("no such file") : fmt::format("cannot open it: {}", std::strerror(e)));
    }
    struct stat st {};
    if (::fstat(fd_, &st) != 0) {
        const int e = errno;
        ::close(fd_);
        throw InputFileError(fmt::format("cannot open it: {}", std::strerror(e)));
    }
    if (!S_ISREG(st.st_mode)) {
        ::close(fd_);
        throw InputFileError(S_ISDIR(st.st_mode) ? "is a directory, not a regular file" : "not a regular file (a device, FIFO or socket)");
    }
    size_ = uint64_t(st.st_size);
}

InputFile::~InputFile() { ::close(fd_); }

std::string InputFile::read_all(uint64_t max_bytes) const {
    if (size_ > max_bytes)
        throw InputFileError(max_bytes % (uint64_t(1) << 20) == 0
                                 ? fmt::format("a file of {} bytes; at most {} MiB are read", size_, max_bytes >> 20)
                                 : fmt::format("a file of {} bytes; at most {} bytes are read", size_, max_bytes));
    std::string text(size_t(size_), '\0');
    for (size_t at = 0; at < text.size();) {
        const ssize_t got = ::pread(fd_, text.data() + at, text.size() - at, off_t(at));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) throw InputFileError(fmt::format("read error: {}", std::strerror(errno)));
        if (got == 0) {  // it shrank while being read
            text.resize(at);
            break;
        }
        at += size_t(got);
    }
    return text;
}

std::string read_input_file(const std::string& path, uint64_t max_bytes) { return InputFile(path).read_all(max_bytes); }

void require_input_file(const std::string& path) { InputFile file(path); }

}  // namespace pathlab
