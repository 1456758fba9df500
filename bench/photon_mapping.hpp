#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct PhotonMappingOptions {
    int light_paths = 262144;  // light paths traced for the photon set
    int size = 256;            // queries: one visible point per pixel of a size x size image
    float radius_factor = 0.005f;  // query radius, times the scene's bounding-sphere radius
    int repeats = 5;
    std::vector<std::string> scenes{"2", "4", "7", "caustic.xml", "sds-caustic.xml"};
    int equal_time_size = 64;        // the equal-time table: image size,
    double equal_time_seconds = 4;   // seconds per render,
    int equal_time_repeats = 3;      // rounds (medians reported)
    int ref_spp = 2048;              // and the reference's samples per pixel (bdpt; vcm where bdpt cannot see all light)
};

// `pathlab_bench pm`: photons per second, the two range searches (hashed grid, nanoflann's
// k-d tree): build time, query time, memory per photon; vcm's iterations (photons, memory per
// photon, time); equal-time RMSE of the photon methods next to pt-mis and bdpt.
void photon_mapping_suite(const PhotonMappingOptions& o);

}  // namespace pathlab::bench
