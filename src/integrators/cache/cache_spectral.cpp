// ic and pbgi in spectral mode (docs/spectral.md, "Spectral ic and pbgi"), in a file of their own
// so that ic.cpp's and pbgi.cpp's RGB code compiles as before. Exact at the wavelengths: the
// first hit's emission and direct light, the Phong lobe's indirect light, pt-mis wherever the
// cache does not serve, and ic's own gather ray where no record covers a point. Approximated:
// the cached indirect irradiance, which the caches hold in RGB (records gathered in RGB mode),
// becomes a spectrum as an emitter's RGB does (illuminant_spectrum: the unbounded upsampling
// times D65 at unit luminance), so its film colour is the cached RGB (to the table's error) but
// its spectral shape is a guess: rho_d(lambda) E(lambda) is not the spectrum of the light that
// actually arrives after a diffuse bounce.
#include "integrators/cache/first_hit_spectral.hpp"
#include "integrators/cache/ic.hpp"
#include "integrators/cache/pbgi.hpp"
#include "core/sampling.hpp"

namespace pathlab {

Spectrum4 IrradianceCaching::radiance_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, SampledWavelengths& wl) const {
    return first_hit_radiance_spectral(scene, ray, sampler, rules_, options_.hide_emitters, wl,
                                       [&](const ShadingPoint& sp, Sampler& s, SampledWavelengths& w) -> Spectrum4 {
                                           Rgb E;
                                           if (cache_.interpolate(sp.p, sp.frame.n, E)) return illuminant_spectrum(E, w);
                                           // indirect_irradiance's gather ray (the same random numbers), spectrally.
                                           const Vec3f d = sp.frame.to_world(square_to_cosine_hemisphere(s.next2d()));
                                           Intersection hit;
                                           if (!scene.intersect(spawn_ray(sp.p, sp.ng, d), hit)) return Spectrum4(0.0f);
                                           return pt_mis_spectral_from_hit(scene, hit, d, 1, s, rules_, false, -1, Spectrum4(0.0f), w) * kPi;
                                       });
}

Spectrum4 PointBasedGi::radiance_spectral(const Scene& scene, const Ray& ray, Sampler& sampler, SampledWavelengths& wl) const {
    if (tree_.surfels().empty())
        return first_hit_radiance_spectral(scene, ray, sampler, rules_, options_.hide_emitters, wl,
                                           [](const ShadingPoint&, Sampler&, SampledWavelengths&) { return Spectrum4(0.0f); });
    return first_hit_radiance_spectral(scene, ray, sampler, rules_, options_.hide_emitters, wl,
                                       [&](const ShadingPoint& sp, Sampler&, SampledWavelengths& w) {
                                           return illuminant_spectrum(indirect_irradiance(sp, ray.d), w);
                                       });
}

}  // namespace pathlab
