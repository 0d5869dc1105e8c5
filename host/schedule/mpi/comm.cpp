// portalsim's MPI module: schedule/mpi/comm.h's table over the MPI library it is linked with.
#include "schedule/mpi/comm.h"

#include <mpi.h>

#include <cstdlib>

namespace {

int init(int* rank, int* size) {
  int provided = 0;
  if (const int rc = MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided); rc != MPI_SUCCESS) return rc;
  std::atexit([] {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  });
  if (const int rc = MPI_Comm_rank(MPI_COMM_WORLD, rank); rc != MPI_SUCCESS) return rc;
  return MPI_Comm_size(MPI_COMM_WORLD, size);
}

int all_gather_int(int mine, int* all) { return MPI_Allgather(&mine, 1, MPI_INT, all, 1, MPI_INT, MPI_COMM_WORLD); }

int all_gather_bytes(const char* mine, int n, char* all, const int* sizes, const int* offsets) {
  return MPI_Allgatherv(mine, n, MPI_CHAR, all, sizes, offsets, MPI_CHAR, MPI_COMM_WORLD);
}

const portalsim::mpi::Comm kComm{portalsim::mpi::kCommVersion, init, all_gather_int, all_gather_bytes};

}  // namespace

extern "C" __attribute__((visibility("default"))) const portalsim::mpi::Comm* portalsim_mpi_comm() { return &kComm; }
