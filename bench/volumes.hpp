#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct VolumesOptions {
    int size = 128;        // image width and height
    double seconds = 4;    // per timed render
    int repeats = 3;       // interleaved rounds (medians reported)
    int ref_spp = 2048;    // the volpath reference's samples per pixel
    int fixed_spp = 32;    // per render of the comparison without media
    std::vector<std::string> plain_scenes{"2-ceiling-diffuse.xml", "5-box-glossy.xml", "6-env-diffuse.xml"};
    std::vector<std::string> scenes{"fog-point.xml", "fog-ceiling.xml", "fog-box.xml", "fog-env.xml", "smoke.xml"};
};

// `pathlab_bench volumes`: volpath's time per sample against pt-mis on scenes without media;
// volpath's samples per second on the fog and smoke scenes (next to
// pt-mis, which ignores the media, on the same scenes); equal-time RMSE of volpath with and
// without MIS; the cost of a sample as the fog's optical thickness grows (0.1, 1, 10).
void volumes_suite(const VolumesOptions& o);

}  // namespace pathlab::bench
