#include <csignal>

#include "app/cli.hpp"
#include "distributed/mpi_ranks.hpp"

int main(int argc, char** argv) {
    // A write past the file-size limit (ulimit -f) fails with EFBIG, which the writers report
    // (naming the file, removing their temporary, exit 1), rather than killing pathlab silently.
    std::signal(SIGXFSZ, SIG_IGN);
    // Under mpirun (or another MPI launcher) the ranks render together; otherwise MPI is not started.
    const std::unique_ptr<pathlab::MpiSession> mpi = pathlab::MpiSession::join(argc, argv);
    return pathlab::run_cli(argc, argv, mpi ? &mpi->ranks() : nullptr);
}
