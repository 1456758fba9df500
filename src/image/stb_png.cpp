#include "image/stb_png.hpp"

#include <cstdlib>
#include <cstring>
#include <memory>

namespace {

// stb_image's allocations, counted against a budget for the decode running on this thread.
struct Budget {
    size_t limit = 0, used = 0;
    bool exceeded = false;
};
thread_local Budget* t_budget = nullptr;

// Each block carries its size in front of it (16 bytes, keeping malloc's alignment).
constexpr size_t kHeader = 16;

size_t block_size(void* p) {
    size_t n;
    std::memcpy(&n, static_cast<char*>(p) - kHeader, sizeof n);
    return n;
}

bool admit(size_t old_size, size_t new_size) {
    if (!t_budget) return true;
    const size_t others = t_budget->used - old_size;
    if (new_size > t_budget->limit || others > t_budget->limit - new_size) {
        t_budget->exceeded = true;
        return false;
    }
    t_budget->used = others + new_size;
    return true;
}

void* budget_malloc(size_t n) {
    if (n > SIZE_MAX - kHeader || !admit(0, n)) return nullptr;
    char* base = static_cast<char*>(std::malloc(n + kHeader));
    if (!base) {
        if (t_budget) t_budget->used -= n;
        return nullptr;
    }
    std::memcpy(base, &n, sizeof n);
    return base + kHeader;
}

void budget_free(void* p) {
    if (!p) return;
    if (t_budget) t_budget->used -= block_size(p);
    std::free(static_cast<char*>(p) - kHeader);
}

void* budget_realloc(void* p, size_t n) {
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

}  // namespace

#define STBI_MALLOC(sz) budget_malloc(sz)
#define STBI_REALLOC(p, newsz) budget_realloc(p, newsz)
#define STBI_FREE(p) budget_free(p)
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#define STBI_NO_LINEAR
#define STBI_NO_HDR
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wunused-function"
#pragma clang diagnostic ignored "-Wsign-compare"
#pragma clang diagnostic ignored "-Wimplicit-fallthrough"
#else
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wmisleading-indentation"
#endif
#include <stb_image.h>
#if defined(__clang__)
#pragma clang diagnostic pop
#else
#pragma GCC diagnostic pop
#endif

namespace pathlab::io {

PngDecodeResult decode_png_rgb8(const uint8_t* data, size_t size, size_t budget, Image8& out) {
    PngDecodeResult result;
    Budget b;
    b.limit = budget;
    t_budget = &b;
    int w = 0, h = 0, n = 0;
    stbi_uc* pixels = stbi_load_from_memory(data, int(size), &w, &h, &n, 3);
    if (!pixels) {
        t_budget = nullptr;
        result.over_budget = b.exceeded;
        const char* why = stbi_failure_reason();
        result.error = why ? why : "unknown error";
        return result;
    }
    const size_t bytes = size_t(w) * size_t(h) * 3;
    try {
        out.width = w, out.height = h;
        out.rgb.assign(pixels, pixels + bytes);
    } catch (...) {
        stbi_image_free(pixels);
        t_budget = nullptr;
        throw;
    }
    stbi_image_free(pixels);
    t_budget = nullptr;
    result.ok = true;
    return result;
}

}  // namespace pathlab::io
