// A photon: where a light subpath met a non-Dirac surface (or scattered in a medium), the direction it came from and the
// power it carries (the light subpath's throughput there, for one light path; divided by the
// number of light paths when density is estimated), in the colour of transport T.
#pragma once

#include <cstdint>

#include "integrators/bidir/path_vertex.hpp"
#include "integrators/common/path_rules.hpp"
#include "integrators/common/transport.hpp"

namespace pathlab {

template <class T>
struct Photon {
    Vec3f p;
    Vec3f wi;                 // world direction back towards where the photon came from
    ColourOf<T> power;        // throughput of its light path up to here
    uint16_t vertex : 15;     // its index j on the light subpath (y_0 is on the light): j - 1 bounces before it
    uint16_t dispersed : 1;   // its light path met a dispersive interface: it carries the hero alone
    // Where it scattered in a medium (its power includes sigma_s there): that medium; -1 on a surface.
    int16_t medium = -1;

    bool in_medium() const { return medium >= 0; }
};
static_assert(kMaxBounces + 1 < (1 << 15));

// The `medium` of a photon at light vertex v.
template <class Vertex>
int16_t photon_medium(const Vertex& v) { return v.kind == VertexKind::Medium ? int16_t(v.medium) : int16_t(-1); }

// The sum of f(x, wo, wi_p) power_p (times any weight) over the photons merged at one camera
// vertex, in transport T's colour. Spectral mode keeps photons that carry the hero alone apart
// (docs/spectral.md "Spectral photon mapping"): the factor 4 of terminate_secondary belongs once
// to the whole camera + light path, so a dispersed photon's lane 0 counts 4 times against a camera
// path of 4 lanes and once against a dispersed camera path (whose hero pdf is p/4 already). RGB
// photons are never dispersed.
template <class T>
class MergeSum {
public:
    void add(const ColourOf<T>& c, bool dispersed) {
        if (dispersed) hero_ += c, any_hero_ = true;
        else full_ += c;
    }
    ColourOf<T> total(const WavelengthsOf<T>& camera_wl) const {
        if (!any_hero_) return full_;
        return full_ + hero_lane(hero_) * (camera_wl.secondary_terminated() ? 1.0f : 4.0f);
    }

private:
    ColourOf<T> full_{0.0f}, hero_{0.0f};
    bool any_hero_ = false;
};

}  // namespace pathlab
