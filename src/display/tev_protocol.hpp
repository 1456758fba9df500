// tev's IPC protocol (github.com/Tom94/tev, src/Ipc.cpp), the packets pathlab sends to a running
// tev to show a render as it converges. Every packet is little-endian: a uint32 length of the
// whole packet (these 4 bytes included), a type byte, then the fields; a string is its bytes
// and a terminating NUL, a bool one byte (0 or 1).
//   CreateImage (4):   grab_focus, name, int32 width, int32 height, int32 channel count, the
//                      channel names
//   UpdateImageV3 (6): grab_focus, name, int32 channel count, the channel names, int32 x, y,
//                      width, height of the region, int64 offset and int64 stride of each
//                      channel into the float32 data that follows (channel c of the region's
//                      pixel p is data[offset_c + p * stride_c], pixels row by row)
//   CloseImage (2):    name
// tev accepts packets of up to 4 GiB but holds each in memory; pathlab sends a film as row
// stripes of at most kStripeBytes of pixel data.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pathlab::tev {

enum class PacketType : uint8_t { CloseImage = 2, CreateImage = 4, UpdateImageV3 = 6 };

constexpr int kDefaultPort = 14158;
constexpr size_t kStripeBytes = size_t(8) << 20;

std::vector<char> create_image(const std::string& name, int width, int height, std::span<const std::string> channels,
                               bool grab_focus = false);
// The region (x, y, width, height) of an image whose pixels hold channels.size() interleaved
// floats: `pixels` starts at the region's first pixel and has `row_pitch` floats per image row.
std::vector<char> update_image(const std::string& name, std::span<const std::string> channels, int x, int y, int width, int height,
                               const float* pixels, size_t row_pitch, bool grab_focus = false);
// The same packet in two parts, to send without copying the pixels: its header (whose length
// field counts the data too), then the region's rows as they are in `pixels`.
std::vector<char> update_image_header(const std::string& name, std::span<const std::string> channels, int x, int y, int width,
                                      int height, bool grab_focus = false);
std::vector<char> close_image(const std::string& name);

// Rows per UpdateImage packet for an image `width` pixels wide with `channels` channels.
int stripe_rows(int width, int channels);

}  // namespace pathlab::tev
