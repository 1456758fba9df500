#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct DifferentiableOptions {
    int size = 128;         // image width and height
    int spp = 16;           // samples per pixel of every render
    int repeats = 5;        // interleaved rounds (medians reported)
    std::vector<int> scenes{2, 3, 5};
    std::string texture_scene = PATHLAB_SOURCE_DIR "/scenes/diff-texture.xml";  // a row with texels ("": none)
    std::string media_scene = PATHLAB_SOURCE_DIR "/scenes/fog-box.xml";  // a row in a medium, volpath's estimator ("": none)
};

// `pathlab_bench diff`: the CPU cost of one gradient evaluation (path replay: primal + replay per
// sample) and of one optimisation iteration (the loss's image + the gradient) relative to one
// primal render (pt-mis; volpath in a scene with media) at equal spp, with every parameter of the scene bound; and the memory of
// a gradient evaluation against spp and path depth (heap allocations and their bytes: no
// per-path tape).
void differentiable_suite(const DifferentiableOptions& o);

}  // namespace pathlab::bench
