#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct BidirectionalOptions {
    int size = 64;           // image width and height for the equal-time table
    double seconds = 4.0;    // per timed render
    int repeats = 3;         // timed pairs per scene (medians reported)
    int ref_spp = 2048;      // bdpt samples per pixel of each scene's reference
    // Course scenes by index, shipped scene files by name (under scenes/).
    std::vector<std::string> scenes{"0", "1", "2", "3", "4", "5", "6", "7", "lampshade.xml", "caustic.xml", "smallvcm-box.xml"};
    int throughput_size = 128;  // image size for the throughput table
    double throughput_seconds = 3.0;
};

// `pathlab_bench bdpt`: equal-time RMSE of bdpt against pt-mis on the course scenes and the
// shipped BDPT scenes, decomposed into variance per sample and time per sample; and bdpt's
// subpaths per second next to pt-mis's paths per second.
void bidirectional_suite(const BidirectionalOptions& o);

}  // namespace pathlab::bench
