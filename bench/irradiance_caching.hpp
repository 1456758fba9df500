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

// `pathlab_bench ic`: equal-time RMSE of ic, pt-mis and bdpt at short budgets on the diffuse
// course scenes, ic's record counts and cache build times, and its bias left at a long budget.
void irradiance_caching_suite(const IrradianceCachingOptions& o);

}  // namespace pathlab::bench
