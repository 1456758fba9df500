// A photon: where a light subpath met a non-Dirac surface (or scattered in a medium), the direction it came from and the
// power it carries (the light subpath's throughput there, for one light path; divided by the
// number of light paths when density is estimated), in the colour of transport T.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/memory.hpp"

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

// A photon pass's memory, checked before it is traced when it is large (2^20 light paths or
// more): the first 256 light paths (trace(j, path) fills light path j's vertices) give the
// photons per path, and NotEnoughMemory refuses the pass if `paths` of them, bytes_per_photon
// each, would not fit, saying which option (`option`, e.g. "--photons") lowers it and how far.
template <class Vertex, typename Trace>
void check_photon_memory(const std::string& who, size_t paths, uint64_t bytes_per_photon, const std::string& option, Trace&& trace) {
    if (paths < (size_t(1) << 20)) return;
    constexpr size_t kPilot = 256;
    std::vector<Vertex> path;
    size_t photons = 0;
    for (size_t j = 0; j < kPilot; ++j) {
        trace(j, path);
        for (size_t v = 1; v < path.size(); ++v)
            if ((path[v].kind == VertexKind::Surface || path[v].kind == VertexKind::Medium) && path[v].connectible()) ++photons;
    }
    const double per_path = double(photons) / kPilot;
    check_memory(
        double(paths) * per_path * double(bytes_per_photon),
        [&] { return fmt::format("{}'s {} light paths (about {:.1f} photons each, {} bytes per photon)", who, paths, per_path, bytes_per_photon); },
        [&](uint64_t available) {
            return fmt::format(": lower {} (about {} light paths fit)", option,
                               uint64_t(double(available) / (std::max(per_path, 1e-3) * double(bytes_per_photon))));
        });
}

}  // namespace pathlab
