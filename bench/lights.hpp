#pragma once

#include <vector>

namespace pathlab::bench {

struct LightsOptions {
    int size = 128;          // image width and height of the timed renders
    double seconds = 2.0;    // per timed render
    int repeats = 3;         // interleaved rounds (medians reported)
    std::vector<int> scenes{6, 7};
    int map_width = 512;     // the constant map's resolution (width x width / 2)
};

// `pathlab_bench lights`: the cost per sample of an environment map against the constant
// environment (pt-mis and bdpt on the course's sky scenes), the cost of one light sample, one
// pdf and one lookup, and the cost of spot and IES lights against the point light.
void lights_suite(const LightsOptions& o);

}  // namespace pathlab::bench
