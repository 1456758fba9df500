#include "image/file_io.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <limits>

#include <fmt/format.h>

#include "image/image_io.hpp"

namespace pathlab::io {
namespace fs = std::filesystem;

namespace {

std::string errno_text(int e) { return std::strerror(e); }

constexpr size_t kWriteBuffer = size_t(1) << 16;
// Room for ".NAME.pathlab-tmp-PID-N" within the usual 255-byte limit of a file name.
constexpr size_t kMaxNameInTemporary = 200;

fs::path directory_of(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? fs::path(".") : parent;
}

void ensure_parent_directory(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty()) return;
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) throw ImageIoError(fmt::format("{}: cannot create directory {}: {}", path, parent.string(), ec.message()));
}

// Creates a new temporary file for `path` (O_EXCL: never an existing file); returns its
// descriptor and name.
std::pair<int, std::string> create_temporary(const std::string& path) {
    static std::atomic<unsigned> counter{0};
    const std::string dir = fs::path(path).parent_path().string();
    const std::string prefix = temporary_prefix(path);
    for (int attempt = 0;; ++attempt) {
        const std::string name = fmt::format("{}{}-{}", prefix, getpid(), counter++);
        const std::string tmp = dir.empty() ? name : (fs::path(dir) / name).string();
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) return {fd, tmp};
        const int e = errno;
        if (e == EEXIST && attempt < 100) continue;
        throw ImageIoError(fmt::format("{}: cannot create a temporary file in {}: {}", path, directory_of(path).string(), errno_text(e)));
    }
}

bool process_exists(long pid) {
    if (pid <= 0 || pid > std::numeric_limits<pid_t>::max()) return false;
    return ::kill(pid_t(pid), 0) == 0 || errno != ESRCH;  // EPERM: it exists, owned by someone else
}

}  // namespace

void ByteSource::throw_truncated(uint64_t offset, size_t n) const {
    throw ImageIoError(fmt::format("{}: unexpected end of file ({} bytes wanted at offset {}, the file has {} bytes)", name_, n,
                                   offset, size_));
}

MemorySource::MemorySource(const void* data, size_t size, std::string name)
    : ByteSource(std::move(name), size), data_(static_cast<const uint8_t*>(data)) {}

void MemorySource::read(uint64_t offset, void* dst, size_t n) const {
    if (offset > size() || n > size() - offset) throw_truncated(offset, n);
    if (n) std::memcpy(dst, data_ + offset, n);
}

namespace {

std::unique_ptr<InputFile> open_image_file(const std::string& path) {
    try {
        return std::make_unique<InputFile>(path);
    } catch (const InputFileError& e) {
        throw ImageIoError(fmt::format("{}: {}", path, e.what()));
    }
}

}  // namespace

FileSource::FileSource(const std::string& path) : FileSource(path, open_image_file(path)) {}

FileSource::FileSource(const std::string& path, std::unique_ptr<InputFile> file) : ByteSource(path, file->size()), file_(std::move(file)) {}

void FileSource::read(uint64_t offset, void* dst, size_t n) const {
    if (offset > size() || n > size() - offset) throw_truncated(offset, n);
    auto* out = static_cast<char*>(dst);
    while (n > 0) {
        const ssize_t got = ::pread(file_->fd(), out, std::min<size_t>(n, size_t(1) << 30), off_t(offset));
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) throw ImageIoError(fmt::format("{}: read error: {}", name(), errno_text(errno)));
        if (got == 0) throw ImageIoError(fmt::format("{}: the file ended at byte {} while being read (it is {} bytes long)", name(), offset, size()));
        out += got, offset += uint64_t(got), n -= size_t(got);
    }
}

Bytes::Bytes(const ByteSource& src, uint64_t max_bytes) : data_(src.data()), size_(size_t(std::min(src.size(), max_bytes))) {
    if (!data_) {
        storage_.resize(size_);
        src.read(0, storage_.data(), size_);
        data_ = storage_.data();
    }
}

FdWriter::FdWriter(int fd, std::string name) : fd_(fd), name_(std::move(name)) {
    buffer_.reserve(kWriteBuffer);
    const off_t at = ::lseek(fd, 0, SEEK_CUR);
    buffer_start_ = at > 0 ? uint64_t(at) : 0;
}

void FdWriter::throw_error() const { throw ImageIoError(error_); }

void FdWriter::fail(const std::string& reason) {
    if (error_.empty()) error_ = fmt::format("{}: cannot write: {}", name_, reason);
    throw_error();
}

void FdWriter::write_out(const char* data, size_t n) {
    while (n > 0) {
        const ssize_t put = ::write(fd_, data, std::min<size_t>(n, size_t(1) << 30));
        if (put < 0 && errno == EINTR) continue;
        if (put < 0) fail(errno_text(errno));
        if (put == 0) fail("the file system accepted no more data");
        data += put, n -= size_t(put), buffer_start_ += uint64_t(put);
    }
}

void FdWriter::flush() {
    if (failed()) throw_error();
    write_out(buffer_.data(), buffer_.size());
    buffer_.clear();
}

void FdWriter::write(const void* data, size_t n) {
    if (failed()) throw_error();
    const char* p = static_cast<const char*>(data);
    if (buffer_.size() + n > kWriteBuffer) {
        flush();
        if (n >= kWriteBuffer) return write_out(p, n);
    }
    buffer_.insert(buffer_.end(), p, p + n);
}

void FdWriter::put(const void* data, size_t n) noexcept {
    try {
        write(data, n);
    } catch (...) {
        if (error_.empty()) error_ = fmt::format("{}: cannot write", name_);
    }
}

void FdWriter::seek(uint64_t position) {
    flush();
    if (::lseek(fd_, off_t(position), SEEK_SET) < 0) fail(errno_text(errno));
    buffer_start_ = position;
}

std::string temporary_prefix(const std::string& path) {
    std::string name = fs::path(path).filename().string();
    if (name.size() > kMaxNameInTemporary) name.resize(kMaxNameInTemporary);
    return "." + name + ".pathlab-tmp-";
}

void remove_stale_temporaries(const std::string& path) {
    const std::string prefix = temporary_prefix(path);
    const fs::path dir = directory_of(path);
    DIR* d = ::opendir(dir.c_str());
    if (!d) return;
    std::vector<std::string> stale;
    while (const dirent* e = ::readdir(d)) {
        const std::string name = e->d_name;
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        // The rest must be exactly "PID-N".
        const std::string rest = name.substr(prefix.size());
        const size_t dash = rest.find('-');
        if (dash == 0 || dash == std::string::npos || dash + 1 == rest.size() || dash > 9) continue;
        const auto digits = [](const std::string& s) { return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; }); };
        if (!digits(rest.substr(0, dash)) || !digits(rest.substr(dash + 1))) continue;
        const long pid = std::stol(rest.substr(0, dash));
        if (pid == long(getpid()) || process_exists(pid)) continue;
        stale.push_back(name);
    }
    ::closedir(d);
    for (const std::string& name : stale) {
        struct stat st {};
        const std::string full = (dir / name).string();
        if (::lstat(full.c_str(), &st) == 0 && S_ISREG(st.st_mode)) ::unlink(full.c_str());
    }
}

void write_file_atomically(const std::string& path, const std::function<void(FdWriter&)>& write) {
    ensure_parent_directory(path);
    std::error_code ec;
    const bool existed = fs::exists(fs::symlink_status(path, ec));
    remove_stale_temporaries(path);
    auto [fd, tmp] = create_temporary(path);
    try {
        FdWriter writer(fd, path);
        write(writer);
        writer.flush();
        // fsync is refused by some special files and file systems (EINVAL, EROFS): not an error.
        if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS && errno != ENOTSUP) writer.fail(errno_text(errno));
        const int closing = fd;
        fd = -1;
        if (::close(closing) != 0) writer.fail(errno_text(errno));
        if (::rename(tmp.c_str(), path.c_str()) != 0) writer.fail(fmt::format("cannot rename {} onto it: {}", tmp, errno_text(errno)));
    } catch (const ImageIoError& e) {
        if (fd >= 0) ::close(fd);
        ::unlink(tmp.c_str());
        throw ImageIoError(fmt::format("{} ({})", e.what(), existed ? "the existing file was left as it was" : "no file was written"));
    } catch (...) {
        if (fd >= 0) ::close(fd);
        ::unlink(tmp.c_str());
        throw;
    }
    // Make the rename itself durable (best effort: not every file system can sync a directory).
    const int dir_fd = ::open(directory_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir_fd >= 0) {
        (void)::fsync(dir_fd);
        ::close(dir_fd);
    }
}

void check_image_size(const std::string& name, uint64_t width, uint64_t height, uint64_t max_pixels, unsigned bytes_per_pixel) {
    if (width == 0 || height == 0) throw ImageIoError(fmt::format("{}: the image is {}x{} pixels: empty", name, width, height));
    if (width <= max_pixels && height <= max_pixels && width * height <= max_pixels) return;
    const long double pixels = static_cast<long double>(width) * static_cast<long double>(height);  // exact below 2^64
    const double gib = double(pixels) * bytes_per_pixel / double(uint64_t(1) << 30);
    throw ImageIoError(fmt::format("{}: the image is {}x{} = {:.0f} pixels, more than the {} pixels{} pathlab reads; it would need {:.1f} GiB of memory",
                                   name, width, height, pixels, max_pixels, max_pixels == kMaxImagePixels ? " (2^28)" : "", gib));
}

void probe_writable(const std::string& path) {
    ensure_parent_directory(path);
    auto [fd, tmp] = create_temporary(path);
    ::close(fd);
    ::unlink(tmp.c_str());
}

}  // namespace pathlab::io
