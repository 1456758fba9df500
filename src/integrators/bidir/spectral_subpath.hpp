// A bdpt subpath in spectral mode (docs/spectral.md, "Spectral bdpt and the light tracer"):
// its vertices exactly as RGB mode makes them (positions, materials, densities and Dirac flags,
// which the MIS weights read; their RGB `beta` unused), their throughputs at the camera
// sample's wavelengths, and where the subpath passed a dispersive interface.
#pragma once

#include <limits>
#include <vector>

#include "integrators/bidir/path_vertex.hpp"
#include "spectral/spectrum4.hpp"

namespace pathlab {

struct SpectralSubpath {
    std::vector<PathVertex> vertices;
    std::vector<Spectrum4> beta;  // beta[i]: the throughput up to and including vertex i
    // The first vertex reached through a dispersive interface (sampled with the hero wavelength's
    // index): from there on the subpath carries the hero alone (beta's other lanes are 0).
    int dispersed_from = std::numeric_limits<int>::max();

    size_t size() const { return vertices.size(); }
    bool dispersed(int i) const { return i >= dispersed_from; }
    void clear() {
        vertices.clear();
        beta.clear();
        dispersed_from = std::numeric_limits<int>::max();
    }
    void push_back(const PathVertex& v, const Spectrum4& b) {
        vertices.push_back(v);
        beta.push_back(b);
    }
};

}  // namespace pathlab
