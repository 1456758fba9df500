#include "display/tev_protocol.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace pathlab::tev {
namespace {

// Appends little-endian fields and keeps the leading length up to date at the end.
class PacketWriter {
public:
    explicit PacketWriter(PacketType type) {
        bytes_.resize(4);
        bytes_.push_back(char(type));
    }
    template <class T>
    void put(T value) {
        static_assert(std::is_trivially_copyable_v<T>);
        char b[sizeof(T)];
        std::memcpy(b, &value, sizeof(T));
        // pathlab builds on little-endian machines only (checkpoints rely on it too).
        bytes_.insert(bytes_.end(), b, b + sizeof(T));
    }
    void put_bool(bool v) { bytes_.push_back(v ? 1 : 0); }
    void put_string(const std::string& s) {
        if (s.find('\0') != std::string::npos) throw std::invalid_argument("tev: a name may not contain a NUL byte");
        bytes_.insert(bytes_.end(), s.begin(), s.end());
        bytes_.push_back('\0');
    }
    // `data_after`: bytes of the packet that the caller sends after these.
    std::vector<char> finish(size_t data_after = 0) {
        if (bytes_.size() + data_after > UINT32_MAX) throw std::length_error("tev: a packet of over 4 GiB");
        const uint32_t n = uint32_t(bytes_.size() + data_after);
        std::memcpy(bytes_.data(), &n, 4);
        return std::move(bytes_);
    }

private:
    std::vector<char> bytes_;
};

}  // namespace

std::vector<char> create_image(const std::string& name, int width, int height, std::span<const std::string> channels, bool grab_focus) {
    PacketWriter w(PacketType::CreateImage);
    w.put_bool(grab_focus);
    w.put_string(name);
    w.put(int32_t(width));
    w.put(int32_t(height));
    w.put(int32_t(channels.size()));
    for (const std::string& c : channels) w.put_string(c);
    return w.finish();
}

std::vector<char> update_image_header(const std::string& name, std::span<const std::string> channels, int x, int y, int width,
                                      int height, bool grab_focus) {
    if (channels.empty() || width <= 0 || height <= 0) throw std::invalid_argument("tev: an empty update");
    const size_t n = channels.size();
    PacketWriter w(PacketType::UpdateImageV3);
    w.put_bool(grab_focus);
    w.put_string(name);
    w.put(int32_t(n));
    for (const std::string& c : channels) w.put_string(c);
    w.put(int32_t(x));
    w.put(int32_t(y));
    w.put(int32_t(width));
    w.put(int32_t(height));
    // The region's pixels are sent interleaved, as pathlab holds them: channel c at c + p * n.
    for (size_t c = 0; c < n; ++c) w.put(int64_t(c));
    for (size_t c = 0; c < n; ++c) w.put(int64_t(n));
    return w.finish(size_t(width) * size_t(height) * n * sizeof(float));
}

std::vector<char> update_image(const std::string& name, std::span<const std::string> channels, int x, int y, int width, int height,
                               const float* pixels, size_t row_pitch, bool grab_focus) {
    std::vector<char> p = update_image_header(name, channels, x, y, width, height, grab_focus);
    const size_t row_bytes = size_t(width) * channels.size() * sizeof(float);
    p.reserve(p.size() + row_bytes * size_t(height));
    for (int r = 0; r < height; ++r) {
        const char* row = reinterpret_cast<const char*>(pixels + size_t(r) * row_pitch);
        p.insert(p.end(), row, row + row_bytes);
    }
    return p;
}

std::vector<char> close_image(const std::string& name) {
    PacketWriter w(PacketType::CloseImage);
    w.put_string(name);
    return w.finish();
}

int stripe_rows(int width, int channels) {
    const size_t row_bytes = std::max<size_t>(1, size_t(width) * size_t(channels) * sizeof(float));
    return int(std::max<size_t>(1, kStripeBytes / row_bytes));
}

}  // namespace pathlab::tev
