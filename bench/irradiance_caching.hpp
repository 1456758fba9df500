#pragma once

#include <vector>

namespace pathlab::bench {

struct IrradianceCachingOptions {
    int size = 256;                          // image width and height
    std::vector<double> budgets{1, 4, 16};  // seconds per render
    int repeats = 3;                         // rounds (medians reported)
    int ref_spp = 2048;                      // the pt-mis reference's samples per pixel
    std::vector<int> scenes{2, 4, 6};
};

struct GatherAccuracyOptions {
    std::vector<int> scenes{2, 4, 6};
    int points = 300;                        // first hits (random positions in a 64x64 image)
    int surfels = 16000;
    std::vector<float> cutoffs{0.01f, 0.03f, 0.1f, 0.3f};
    std::vector<int> resolutions{8, 12, 16};
};

// `pathlab_bench pbgi-gather`: pbgi's gather against the truth it aims at (the irradiance from the
// surfels' radiance on the real surfaces, ray traced), per cutoff and micro-buffer resolution:
// relative RMS and mean error, processor microseconds per gather, clusters and surfels drawn.
void pbgi_gather_suite(const GatherAccuracyOptions& o);

// `pathlab_bench ic`: equal-time RMSE of ic, pbgi, pt-mis and bdpt at short budgets on the
// diffuse course scenes, ic's record counts, pbgi's surfel counts, their build times, and their
// bias left at a long budget.
void irradiance_caching_suite(const IrradianceCachingOptions& o);

}  // namespace pathlab::bench
