// A photon: where a light subpath met a non-Dirac surface, the direction it came from and the
// power it carries (the light subpath's throughput there, for one light path; divided by the
// number of light paths when density is estimated).
#pragma once

#include <cstdint>

#include "core/vec.hpp"

namespace pathlab {

struct Photon {
    Vec3f p;
    Vec3f wi;        // world direction back towards where the photon came from
    Rgb power;       // throughput of its light path up to here
    uint16_t vertex; // its index j on the light subpath (y_0 is on the light): j - 1 bounces before it
};

}  // namespace pathlab
