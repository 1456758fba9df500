#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct DisplayOptions {
    int size = 512;                 // image width and height
    double seconds = 4;             // per timed render
    int repeats = 5;                // interleaved pairs (medians reported)
    std::vector<std::string> algorithms{"pt-mis", "lt"};
    std::string scene = "4";
};

// `pathlab_bench display`: the cost of --display-server (samples per second with and without a
// viewer on loopback that reads every packet), and the time from the start of a render to the
// viewer's first complete image.
void display_suite(const DisplayOptions& o);

}  // namespace pathlab::bench
