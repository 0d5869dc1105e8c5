// The processes of one job: this process alone, or the ranks an MPI launcher (mpirun,
// srun) started. Ranks share nothing but a filesystem and these calls; every rank
// makes the same calls in the same order.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace portalsim {

class Ranks {
 public:
  virtual ~Ranks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Every rank's `mine`, in rank order, on every rank.
  virtual std::vector<std::string> all_gather(const std::string& mine) = 0;
  // Runs `f` on this rank. When it throws on any rank, every rank throws: alone, the
  // error itself; among several, an error of the first failing rank's kind whose message
  // names each failing rank ("rank 1: ...; rank 2: ...").
  void together(const std::function<void()>& f);
};

// This process alone (rank 0 of 1).
std::unique_ptr<Ranks> single_rank();

// The MPI ranks when this process was started by an MPI launcher; null when it was not.
// The first call loads the MPI module (schedule/mpi/comm.h) and initialises MPI, which stays
// up until the process exits. Throws EnvironmentError, naming the module and the loader's
// message, when launched so but the module is missing or cannot load the system's MPI.
Ranks* mpi_ranks();

}  // namespace portalsim
