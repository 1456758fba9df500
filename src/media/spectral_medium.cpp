#include "media/spectral_medium.hpp"

#include <algorithm>

#include "spectral/rgb_spectra.hpp"
#include "spectral/rgb_to_spectrum.hpp"

namespace pathlab {
namespace {

bool is_grey(const Rgb& c) { return c.x == c.y && c.y == c.z; }

// An extinction: flat at a grey's value (RgbUnboundedSpectrum of a grey is exactly that: the
// table's closed form gives sigmoid(0) = 1/2, times 2m), else the unbounded spectrum.
Spectrum4 extinction_spectrum(const Rgb& c, const SampledWavelengths& wl) {
    if (is_grey(c)) return Spectrum4(c.x > 0 ? c.x : 0.0f);
    return unbounded_spectrum(c, wl);
}

// An albedo: flat at a grey's value (the closed form's exact value, without its rounding), else
// the reflectance spectrum.
Spectrum4 albedo_spectrum(const Rgb& a, const SampledWavelengths& wl) {
    if (is_grey(a)) return Spectrum4(std::clamp(a.x, 0.0f, 1.0f));
    return reflectance_spectrum(a, wl);
}

// The albedo of a homogeneous medium (it stores sigma_s = albedo sigma_t).
Rgb homogeneous_albedo(const HomogeneousMedium& h) {
    Rgb a;
    for (int c = 0; c < 3; ++c) a[c] = h.sigma_t[c] > 0 ? h.sigma_s[c] / h.sigma_t[c] : 0.0f;
    return a;
}

float compute_unbounded_spectrum_bound() {
    // The unbounded spectrum looks the table up at a colour of largest channel exactly 1/2; a
    // grey gives sigmoid(0) = 1/2.
    const float largest = std::max(0.5f, RgbToSpectrumTable::srgb().max_node_value_around(0.5f));
    return std::min(2.0f, 2 * largest * (1 + 1e-5f));
}

}  // namespace

bool MediumAtWavelengths::constant_extinction(Spectrum4& sigma_t) const {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) {
        sigma_t = extinction_spectrum(h->sigma_t, wl);
        return true;
    }
    const auto& g = std::get<HeterogeneousMedium>(m);
    if (!g.sigma_t.is_constant()) return false;
    sigma_t = extinction_spectrum(g.sigma_t.constant, wl) * g.scale;
    return true;
}

Spectrum4 MediumAtWavelengths::extinction(const Vec3f& p) const {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) return extinction_spectrum(h->sigma_t, wl);
    const auto& g = std::get<HeterogeneousMedium>(m);
    return extinction_spectrum(g.sigma_t.eval(p), wl) * g.scale;
}

MediumCoefficientsOf<Spectrum4> MediumAtWavelengths::coefficients(const Vec3f& p) const {
    if (const auto* h = std::get_if<HomogeneousMedium>(&m)) {
        const Spectrum4 sigma_t = extinction_spectrum(h->sigma_t, wl);
        return {sigma_t, albedo_spectrum(homogeneous_albedo(*h), wl) * sigma_t};
    }
    const auto& g = std::get<HeterogeneousMedium>(m);
    const Spectrum4 sigma_t = extinction_spectrum(g.sigma_t.eval(p), wl) * g.scale;
    return {sigma_t, albedo_spectrum(g.albedo.eval(p), wl) * sigma_t};
}

MajorantIterator MediumAtWavelengths::majorants(const Vec3f& o, const Vec3f& d, float tmax, float factor, float& scale) const {
    scale = 1;
    Spectrum4 sigma_t;
    if (constant_extinction(sigma_t)) return MajorantIterator::single(0, tmax, sigma_t.max_value() * factor);
    const auto& g = std::get<HeterogeneousMedium>(m);
    scale = spectral_majorant_factor(m) * factor;
    const Vec3f ou(g.sigma_t.to_unit.point(Vec3d(o))), du(g.sigma_t.to_unit.vector(Vec3d(d)));
    return MajorantIterator(*g.majorants, ou, du, 0, tmax);
}

float unbounded_spectrum_bound() {
    static const float bound = compute_unbounded_spectrum_bound();
    return bound;
}

float spectral_majorant_factor(const Medium& m) {
    const auto* g = std::get_if<HeterogeneousMedium>(&m);
    if (!g || g->sigma_t.is_constant() || g->sigma_t.grid->channels == 1) return 1;
    return unbounded_spectrum_bound();
}

}  // namespace pathlab
