// The table of functions that portalsim's MPI module (libportalsim_mpi.so, built from
// comm.cpp) exports. The module links the system's Open MPI and is loaded (dlopen) only when
// an MPI launcher started the process (schedule/ranks.cpp), so the binary itself needs no
// MPI library: under a cluster's mpirun the module loads that MPI's own libmpi, whose
// plugins then match it, and a bundle carries no MPI of its own. Plain C types only, so
// that the table does not depend on the C++ runtime either side was built with. Each
// function returns MPI's error code (0: MPI_SUCCESS).
#pragma once

namespace portalsim::mpi {

// Raised whenever a field below changes, so that a module from another build is refused.
inline constexpr int kCommVersion = 1;

struct Comm {
  int version = kCommVersion;
  // MPI_Init_thread with MPI_THREAD_FUNNELED (only the main thread calls MPI), then this
  // rank and the number of ranks; MPI_Finalize runs at exit.
  int (*init)(int* rank, int* size) = nullptr;
  // MPI_Allgather of one int per rank into `all` (size() ints).
  int (*all_gather_int)(int mine, int* all) = nullptr;
  // MPI_Allgatherv of `n` bytes per rank into `all`, at each rank's `offsets`, `sizes` long.
  int (*all_gather_bytes)(const char* mine, int n, char* all, const int* sizes, const int* offsets) = nullptr;
};

}  // namespace portalsim::mpi

// The module's one exported symbol.
extern "C" const portalsim::mpi::Comm* portalsim_mpi_comm();
