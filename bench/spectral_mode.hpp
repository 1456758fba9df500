#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct SpectralModeOptions {
    std::vector<int> scenes{3, 5};  // course scene indices
    std::vector<std::string> scene_files;  // scene files (media scenes for volpath), after the course scenes
    std::vector<std::string> algorithms{"pt-mis", "bdpt"};  // the two; lt and the others work too
    int size = 128;    // image width and height
    int spp = 8;       // samples per pixel per timed render
    int repeats = 7;   // interleaved rounds (medians reported)
};

// `pathlab_bench spectral-mode`: the cost of spectral mode relative to RGB mode per sample, for
// each integrator that renders spectrally, on course scenes and scene files: RGB and spectral renders of the
// same size and spp interleaved round by round on all threads (the scene built once), ns per
// sample of each and the median of the rounds' ratios (the target: at most 1.6).
void spectral_mode_suite(const SpectralModeOptions& o);

}  // namespace pathlab::bench
