#include "app/cli.hpp"
#include "distributed/mpi_ranks.hpp"

int main(int argc, char** argv) {
    // Under mpirun (or another MPI launcher) the ranks render together; otherwise MPI is not started.
    const std::unique_ptr<pathlab::MpiSession> mpi = pathlab::MpiSession::join(argc, argv);
    return pathlab::run_cli(argc, argv, mpi ? &mpi->ranks() : nullptr);
}
