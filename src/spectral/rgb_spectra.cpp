#include "spectral/rgb_spectra.hpp"

#include <array>
#include <cstring>

namespace pathlab {
namespace {

// The table's lookup of rgb, through a direct-mapped per-thread cache keyed by rgb's bits.
SigmoidPolynomial lookup(const Vec3f& rgb) {
    struct Entry {
        std::array<uint32_t, 3> bits{};
        bool valid = false;
        SigmoidPolynomial poly;
    };
    thread_local std::array<Entry, 256> cache;
    std::array<uint32_t, 3> bits;
    std::memcpy(&bits[0], &rgb.x, 4);
    std::memcpy(&bits[1], &rgb.y, 4);
    std::memcpy(&bits[2], &rgb.z, 4);
    const uint64_t h = (uint64_t(bits[0]) * 0x9e3779b97f4a7c15ull) ^ (uint64_t(bits[1]) * 0xc2b2ae3d27d4eb4full) ^
                       (uint64_t(bits[2]) * 0x165667b19e3779f9ull);
    Entry& e = cache[size_t((h >> 32) & 255)];
    if (!e.valid || e.bits != bits) {
        e.poly = RgbToSpectrumTable::srgb()(rgb);
        e.bits = bits;
        e.valid = true;
    }
    return e.poly;
}

Spectrum4 at(const SigmoidPolynomial& poly, const SampledWavelengths& wl) {
    Spectrum4 s;
    for (int i = 0; i < kSpectrumLanes; ++i) s[i] = poly(wl[i]);
    return s;
}

}  // namespace

Spectrum4 unbounded_spectrum(const Rgb& rgb, const SampledWavelengths& wl) {
    // RgbUnboundedSpectrum: 2m sigmoid_{rgb / 2m}, m = max(rgb).
    const float m = std::max(std::max(rgb.x, rgb.y), rgb.z);
    if (!(m > 0)) return Spectrum4(0.0f);
    const float scale = 2 * m;
    return at(lookup(rgb / scale), wl) * scale;
}

Spectrum4 reflectance_spectrum(const Rgb& rgb, const SampledWavelengths& wl) {
    if (std::max(std::max(rgb.x, rgb.y), rgb.z) > 1) return unbounded_spectrum(rgb, wl);
    return at(lookup(rgb), wl);  // RgbAlbedoSpectrum
}

Spectrum4 illuminant_spectrum(const Rgb& rgb, const SampledWavelengths& wl) {
    if (is_black(rgb)) return Spectrum4(0.0f);
    return unbounded_spectrum(rgb, wl) * sample_d65_unit_luminance(wl);
}

}  // namespace pathlab
