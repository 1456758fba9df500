// An emitter's own spectrum, as its scene file gives it (a black body, a `wavelength:value`
// list or a spectrum file): spectral mode sees the emitter with this spectrum instead of its RGB
// colour upsampled (docs/spectral.md, "Emitters with a spectrum"). RGB mode uses `rgb`, the
// spectrum's linear sRGB as an illuminant (clamped to the gamut, as the scene-file reader
// converts it), which is also what the light's own RGB code was given.
#pragma once

#include "core/vec.hpp"
#include "spectral/dense_spectrum.hpp"

namespace pathlab {

struct EmissionSpectrum {
    DenseSpectrum values;  // radiance (intensity, irradiance) per nm, in the emitter's units
    Rgb rgb{0.0f};         // the spectrum's linear sRGB: what the light's RGB emission is a multiple of
};

}  // namespace pathlab
