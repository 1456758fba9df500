// MPI: the ranks of one `mpirun -n N pathlab ...` as a RankGroup (job/rank_group.hpp).
//
// MPI is started only when the process was launched by an MPI launcher (mpirun/mpiexec, or a
// scheduler's srun with PMIx): MpiSession::join looks for the variables those set
// (OMPI_COMM_WORLD_SIZE, PMIX_RANK, PMI_RANK) and otherwise leaves MPI alone, so the plain
// binary starts as fast as before, runs in sandboxes where MPI's singleton start cannot, and a
// test process may run the command line many times (MPI may be initialised once per process).
// PATHLAB_MPI=1 forces MPI on (a launcher this does not know), PATHLAB_MPI=0 off.
#pragma once

#include <memory>

#include "job/rank_group.hpp"

namespace pathlab {

class MpiSession {
public:
    // The ranks of this process's MPI job, or null when it was not launched by MPI.
    static std::unique_ptr<MpiSession> join(int& argc, char**& argv);
    ~MpiSession();  // MPI_Finalize
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
    RankGroup& ranks() { return *ranks_; }
    // Ends every rank at once (MPI_Abort): for a failure on one rank that the others cannot learn of.
    [[noreturn]] static void abort(int code);

private:
    MpiSession();
    std::unique_ptr<RankGroup> ranks_;
};

}  // namespace pathlab
