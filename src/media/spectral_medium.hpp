// A participating medium at a path's 4 wavelengths (spectral mode, docs/spectral.md): the view
// free_flight.hpp's sampling and transmittance take, with the hero wavelength (lane 0) as the
// hero channel.
//
// Coefficients: a medium's RGB extinction becomes an unbounded spectrum (RgbUnboundedSpectrum)
// and its RGB albedo a reflectance spectrum (RgbAlbedoSpectrum), sigma_s(lambda) =
// albedo(lambda) sigma_t(lambda); a grey is flat at its value (the table's closed form for
// greys, without its rounding), so grey media are exactly RGB mode's.
//
// Free flight: the hero wavelength (lane 0) drives distance sampling, with the one-sample
// balance heuristic over the 4 lanes' sampling techniques (Wilkie et al. 2014; pbrt-v4's
// r_u): beta_i = f_i / q and r_k = p_k / q as in medium.hpp, a contribution beta L / mean(r).
// That is unbiased because the 4 wavelengths are exchangeable (the hero and its rotations
// u + i/4 have the same joint law whichever lane is called the hero), so lane 0 as the hero is
// the same as a hero chosen uniformly among the 4. A path left with the hero alone (a
// dispersive interface) divides by r_0 instead: only its own technique could have made it.
//
// Majorants: constant extinction uses the largest lane at the path's wavelengths (exact). A
// grid keeps its scalar majorant grid (built over RGB voxels), multiplied by a bound K on how far
// an unbounded spectrum can rise above its RGB's largest channel (unbounded_spectrum_bound():
// 1 for one-channel grids, whose spectra are flat), so delta and ratio tracking stay unbiased
// for every lane.
#pragma once

#include "media/medium.hpp"
#include "spectral/sampled_wavelengths.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

struct MediumAtWavelengths {
    using Colour = Spectrum4;
    const Medium& m;
    const SampledWavelengths& wl;
    bool constant_extinction(Spectrum4& sigma_t) const;
    Spectrum4 extinction(const Vec3f& p) const;
    MediumCoefficientsOf<Spectrum4> coefficients(const Vec3f& p) const;
    MajorantIterator majorants(const Vec3f& o, const Vec3f& d, float tmax, float factor, float& scale) const;
};

// K: for every rgb >= 0, max over [360, 830] nm of RgbUnboundedSpectrum(rgb) <= K max(rgb).
// Computed once from the table's nodes: the unbounded spectrum looks the table up at rgb / 2
// max(rgb) (largest channel exactly 1/2), where the coefficients are a convex combination of
// the nodes of the two z slices around 1/2, and the sigmoid is increasing, so the spectrum is at
// most the largest node spectrum there; K = 2 x that maximum (a little above, for rounding).
// At most 2 (the sigmoid's bound).
float unbounded_spectrum_bound();

// The factor a medium's RGB majorants are multiplied by in spectral mode: 1 where its
// extinction is a one-channel grid or constant (exact there), else unbounded_spectrum_bound().
float spectral_majorant_factor(const Medium& m);


}  // namespace pathlab
