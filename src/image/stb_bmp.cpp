#include "image/stb_bmp.hpp"

#include <cstdlib>
#include <cstring>
#include <memory>

#define STBI_ONLY_BMP
#include "image/stb_image_unit.hpp"

namespace pathlab::io {

BmpDecodeResult decode_bmp_rgb8(const uint8_t* data, size_t size, size_t budget, Image8& out) {
    return decode_rgb8_within_budget(data, size, budget, out, stbi_load_from_memory, stbi_image_free, stbi_failure_reason);
}

}  // namespace pathlab::io
