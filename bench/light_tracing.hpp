#pragma once

#include <vector>

namespace pathlab::bench {

struct LightTracingOptions {
    int size = 256;          // image size for the throughput table
    double seconds = 2.0;    // per timed render
    int repeats = 3;         // timed pairs per scene (medians reported)
    std::vector<int> scenes{0, 1, 2, 3, 4, 5, 6, 7};
    int splat_size = 512;    // film size for the splat-accumulation comparison
    int splat_repeats = 9;
};

// `pathlab_bench lt`: light paths per second of lt next to camera paths per second of pt-mis
// on the course scenes, and the cost of the two deterministic ways of accumulating splats.
void light_tracing_suite(const LightTracingOptions& o);

}  // namespace pathlab::bench
