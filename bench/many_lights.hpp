#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct ManyLightsOptions {
    int size = 64;           // image width and height
    double seconds = 2.0;    // per timed render
    int repeats = 3;         // interleaved rounds (medians reported)
    int ref_spp = 2048;      // samples per pixel of each reference (bvh, another seed)
    std::vector<std::string> scene_files{"many-lights.xml", "emissive-lamp.xml"};
    std::vector<int> scenes{2, 3, 4, 5};  // course scenes with area lights of several triangles
    std::vector<std::string> algorithms{"direct-mis", "pt-mis"};
    float split = 0.5f;      // --light-split of the splitting bvh column
};

// `pathlab_bench many-lights`: equal-time MSE of next-event estimation's light samplers
// (uniform, power, bvh, bvh with adaptive splitting, ris) on the many-light scenes and the course scenes, as ratios to power; the
// light BVH's build time and memory per 1000 lights.
void many_lights_suite(const ManyLightsOptions& o);

}  // namespace pathlab::bench
