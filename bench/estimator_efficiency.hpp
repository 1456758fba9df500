#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct EfficiencyOptions {
    int size = 128;
    int ref_spp = 4096;
    int spp = 16;
    double seconds = 1.0;
    int repeats = 3;
    std::string scenes = "0,1,2,3,4,5,6,7";
};

// One Markdown table: for each scene and algorithm, RMSE at equal spp, RMSE at equal time,
// spp reached, samples/s and rays/s (timed figures are medians over o.repeats seeds).
void efficiency_table(const EfficiencyOptions& o, const std::vector<std::string>& algorithms,
                      const std::string& reference_algorithm);

}  // namespace pathlab::bench
