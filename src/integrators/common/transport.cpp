#include "integrators/common/transport.hpp"

namespace pathlab {

Spectrum4 light_colour(const Scene& scene, int light, const Rgb& Le, const SampledWavelengths& wl) {
    const EmissionSpectrum* own = scene.light_spectrum(light);
    if (!own) [[likely]]
        return illuminant_spectrum(Le, wl);
    if (is_black(Le)) return Spectrum4(0.0f);
    // Le is the emitter's colour own->rgb times what the light multiplied it by: a scale, a
    // falloff, 1/d^2 (grey: it scales the spectrum), or a spot's projected texture (a colour:
    // it multiplies the spectrum as its upsampled unbounded spectrum). Channels where the
    // spectrum's colour is 0 (clamped out of the gamut) take the largest channel's factor.
    const Rgb& c = own->rgb;
    const int m = c.x >= c.y && c.x >= c.z ? 0 : (c.y >= c.z ? 1 : 2);
    if (!(c[m] > 0)) return Spectrum4(0.0f);
    const float k = Le[m] / c[m];
    Rgb factor;
    bool grey = true;
    for (int i = 0; i < 3; ++i) {
        factor[i] = c[i] > 0 ? Le[i] / c[i] : k;
        grey = grey && std::abs(factor[i] - k) <= 1e-5f * k;
    }
    return own->values.sample(wl) * (grey ? Spectrum4(k) : unbounded_spectrum(factor, wl));
}

}  // namespace pathlab
