#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct PhotonMappingOptions {
    int light_paths = 262144;  // light paths traced for the photon set
    int size = 256;            // queries: one visible point per pixel of a size x size image
    float radius_factor = 0.005f;  // query radius, times the scene's bounding-sphere radius
    int repeats = 5;
    std::vector<std::string> scenes{"2", "4", "7", "caustic.xml"};
};

// `pathlab_bench pm`: photons per second, and the two range searches (hashed grid, nanoflann's
// k-d tree): build time, query time, memory per photon.
void photon_mapping_suite(const PhotonMappingOptions& o);

}  // namespace pathlab::bench
