#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct PerfOptions {
    int size = 512;                  // throughput resolution (the course's)
    double seconds = 1.0;            // per timed render
    int repeats = 3;                 // timed renders per figure (median)
    std::vector<int> scenes{3, 7};
    size_t raw_rays = size_t(1) << 20;
    std::vector<size_t> mesh_sizes{0, 1000, 10000, 100000, 1000000};
    int growth_size = 256;
    int efficiency_size = 256;
    int efficiency_ref_spp = 1024;
    std::vector<double> checkpoints{5, 10, 20};
    std::string json = "out/bench/performance.json";
    // Which tables to measure: throughput, bound (Embree's raw rate against pt-mis's), growth, efficiency.
    std::vector<std::string> sections{"throughput", "bound", "growth", "efficiency"};
    bool has(const std::string& section) const;
};

void performance_suite(const PerfOptions& o);

}  // namespace pathlab::bench
