// Measured complex indices of refraction (eta + i k) of the named conductors, as tabulated
// spectra (core/spectrum.hpp's SampledSpectrum, nm), for the spectral mode to use instead of the
// RGB averages of src/bsdfs/ior.hpp. Sources (the published measurements, through the public
// domain refractiveindex.info database, which reproduces the papers' tables):
//   Au, Ag, Cu  P. B. Johnson and R. W. Christy, "Optical constants of the noble metals",
//               Phys. Rev. B 6, 4370-4379 (1972)
//   Cr          P. B. Johnson and R. W. Christy, "Optical constants of transition metals: Ti, V,
//               Cr, Mn, Fe, Co, Ni, and Pd", Phys. Rev. B 9, 5056-5070 (1974)
//   Al          A. D. Rakic, "Algorithm for the determination of intrinsic optical constants of
//               metal films: application to aluminum", Appl. Opt. 34, 4755-4767 (1995)
//   a-C         amorphous carbon: LLNL CXRO, D. L. Windt et al., Appl. Opt. 27, 246 (1988) and
//               Palik's handbook, as compiled by luxpop.com (Mitsuba 3 names it so)
// Only the measurements from just below 360 nm to just above 830 nm are kept.
#pragma once

#include <string>

#include "core/spectrum.hpp"

namespace pathlab {

struct MeasuredConductor {
    const char* name;
    const char* source;
    SampledSpectrum eta, k;
};

// Au, Ag, Cu, Al, Cr or a-C; nullptr for another name.
const MeasuredConductor* measured_conductor(const std::string& name);
inline const char* kMeasuredConductors = "Au, Ag, Cu, Al, Cr, a-C";

}  // namespace pathlab
