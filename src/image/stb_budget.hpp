// stb_image's allocations held to a budget (included only by src/image's stb decoders,
// stb_png.cpp and stb_jpeg.cpp, through stb_image_unit.hpp, which defines STBI_MALLOC,
// STBI_REALLOC and STBI_FREE as these functions before it includes stb_image.h). Each decodes
// through decode_rgb8_within_budget, which sets t_budget around the decode, so that corrupt data
// cannot make stb allocate without bound.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "image/stb_png.hpp"

namespace {

// stb_image's allocations, counted against a budget for the decode running on this thread.
struct Budget {
    size_t limit = 0, used = 0;
    bool exceeded = false;
};
thread_local Budget* t_budget = nullptr;

// Each block carries its size in front of it (16 bytes, keeping malloc's alignment).
constexpr size_t kHeader = 16;

[[maybe_unused]] size_t block_size(void* p) {
    size_t n;
    std::memcpy(&n, static_cast<char*>(p) - kHeader, sizeof n);
    return n;
}

[[maybe_unused]] bool admit(size_t old_size, size_t new_size) {
    if (!t_budget) return true;
    const size_t others = t_budget->used - old_size;
    if (new_size > t_budget->limit || others > t_budget->limit - new_size) {
        t_budget->exceeded = true;
        return false;
    }
    t_budget->used = others + new_size;
    return true;
}

[[maybe_unused]] void* budget_malloc(size_t n) {
    if (n > SIZE_MAX - kHeader || !admit(0, n)) return nullptr;
    char* base = static_cast<char*>(std::malloc(n + kHeader));
    if (!base) {
        if (t_budget) t_budget->used -= n;
        return nullptr;
    }
    std::memcpy(base, &n, sizeof n);
    return base + kHeader;
}

[[maybe_unused]] void budget_free(void* p) {
    if (!p) return;
    if (t_budget) t_budget->used -= block_size(p);
    std::free(static_cast<char*>(p) - kHeader);
}

[[maybe_unused]] void* budget_realloc(void* p, size_t n) {
    if (!p) return budget_malloc(n);
    const size_t old = block_size(p);
    if (n > SIZE_MAX - kHeader || !admit(old, n)) return nullptr;
    char* base = static_cast<char*>(std::realloc(static_cast<char*>(p) - kHeader, n + kHeader));
    if (!base) {
        if (t_budget) t_budget->used = t_budget->used - n + old;
        return nullptr;
    }
    std::memcpy(base, &n, sizeof n);
    return base + kHeader;
}

// One decode of `size` bytes into 8-bit RGB under `budget`, by the stb_image compiled into the
// calling translation unit (its functions are static there, so they are passed in: stb's
// load_from_memory, image_free and failure_reason).
template <typename Load, typename Release, typename Reason>
pathlab::io::PngDecodeResult decode_rgb8_within_budget(const uint8_t* data, size_t size, size_t budget, pathlab::Image8& out,
                                                      Load load, Release release, Reason reason) {
    pathlab::io::PngDecodeResult result;
    Budget b;
    b.limit = budget;
    t_budget = &b;
    int w = 0, h = 0, n = 0;
    unsigned char* pixels = load(data, int(size), &w, &h, &n, 3);
    if (!pixels) {
        t_budget = nullptr;
        result.over_budget = b.exceeded;
        const char* why = reason();
        result.error = why ? why : "unknown error";
        return result;
    }
    const size_t bytes = size_t(w) * size_t(h) * 3;
    try {
        out.width = w, out.height = h;
        out.rgb.assign(pixels, pixels + bytes);
    } catch (...) {
        release(pixels);
        t_budget = nullptr;
        throw;
    }
    release(pixels);
    t_budget = nullptr;
    result.ok = true;
    return result;
}

}  // namespace
