#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct BidirEfficiencyOptions {
    int size = 512;        // image width and height
    int iterations = 8;    // samples per pixel (vcm, bpm: iterations) of each timed render
    int repeats = 3;       // timed renders per method and scene, interleaved (medians reported)
    int ref_spp = 256;     // bdpt samples per pixel of each scene's reference
    std::vector<std::string> scenes{"smallvcm-box.xml", "smallvcm-lightbox.xml"};  // under scenes/
    std::vector<std::string> algorithms{"pt-mis", "bdpt", "bpm", "vcm"};  // "vcm:radius=R": another first radius
    std::vector<std::string> samplers{"independent", "sobol"};
    int max_depth = -1;    // for every method and the reference (SmallVCM's default, 10 segments, is 9)
    // Images of the first scene rendered elsewhere (another renderer: SmallVCM's .hdr output, say),
    // judged against the same reference: "LABEL:ITERATIONS:SECONDS=FILE".
    std::vector<std::string> judge;
};

// `pathlab_bench bidir`: the bidirectional methods against pt-mis on SmallVCM's kind of scene
// (the issue "Bidirectional methods at expert speed"): seconds per iteration, MSE per sample
// against a long bdpt reference (its noise subtracted), efficiency 1 / (MSE x time) relative to
// pt-mis, vcm's time over bdpt's, and the bytes vcm keeps per light vertex.
void bidir_efficiency_suite(const BidirEfficiencyOptions& o);

}  // namespace pathlab::bench
