#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct DistributedOptions {
    int size = 256;            // image size of the speedup renders
    int spp = 64;              // their samples per pixel
    std::string scene = "3";   // their scene
    int repeats = 5;           // timed runs per figure (medians reported)
    std::vector<int> film_sizes{512, 4096};  // films reduced and checkpointed
};

// `pathlab_bench distributed`: the speedup of 2 MPI ranks x 1 thread over 1 process x 2
// threads (mpirun, the same machine), the film reduction's time across 2 ranks, the checkpoints'
// write and read time and size, and the exact film's accumulation cost next to plain doubles.
void distributed_suite(const DistributedOptions& o, const std::string& self);
// The reduction's part run under mpirun by the suite: prints one line per film size.
void distributed_reduce_worker(const std::vector<int>& film_sizes, int repeats, int argc, char** argv);

}  // namespace pathlab::bench
