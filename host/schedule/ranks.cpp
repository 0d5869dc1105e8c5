#include "schedule/ranks.h"

#include <cstdlib>

#include "base/error.h"
#include "base/module.h"
#include "schedule/mpi/comm.h"

namespace portalsim {

void Ranks::together(const std::function<void()>& f) {
  std::exception_ptr error;
  std::string mine;  // the error's kind (I, O, E, X), then its message
  try {
    f();
  } catch (const InputError& e) {
    error = std::current_exception();
    mine = std::string("I") + e.what();
  } catch (const OutputError& e) {
    error = std::current_exception();
    mine = std::string("O") + e.what();
  } catch (const EnvironmentError& e) {
    error = std::current_exception();
    mine = std::string("E") + e.what();
  } catch (const std::exception& e) {
    error = std::current_exception();
    mine = std::string("X") + e.what();
  }
  if (size() == 1) {
    if (error) std::rethrow_exception(error);
    return;
  }
  const std::vector<std::string> all = all_gather(mine);
  std::string message;
  char kind = 0;
  for (size_t r = 0; r < all.size(); ++r) {
    if (all[r].empty()) continue;
    if (!kind) kind = all[r][0];
    message += (message.empty() ? "" : "; ") + ("rank " + std::to_string(r) + ": ") + all[r].substr(1);
  }
  if (!kind) return;
  if (kind == 'I') throw InputError(message);
  if (kind == 'O') throw OutputError(message);
  if (kind == 'E') throw EnvironmentError(message);
  throw std::runtime_error(message);
}

namespace {

// Set by Open MPI's mpirun, by PMIx launchers (srun --mpi=pmix) and by PMI-1/2 ones.
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
    if (std::getenv(v)) return true;
  return false;
}

class SingleRank final : public Ranks {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  std::vector<std::string> all_gather(const std::string& mine) override { return {mine}; }
};

// The MPI module (schedule/mpi/comm.h), loaded on the first call: it links the system's
// MPI, which must be the launcher's.
const mpi::Comm& load_comm() {
  const std::string file = PORTALSIM_MPI_MODULE;
  ModuleLoad load;
  if (const auto* comm = module_table<mpi::Comm>(file, "portalsim_mpi_comm", mpi::kCommVersion, load)) return *comm;
  if (!load.reason.empty())
    throw EnvironmentError("started by an MPI launcher, but portalsim's MPI module " + file +
                           " did not load: " + load.reason +
                           " (it needs the system's Open MPI, libmpi.so.40, the launcher's own: on Debian, "
                           "apt-get install openmpi-bin)");
  // Each rank would run alone into the same folder: refuse rather than race.
  throw EnvironmentError("started by an MPI launcher, but this portalsim has no MPI module " + file +
                         " (looked in: " + load.tried +
                         "): build it with libopenmpi-dev installed (CMake finds it), or run without mpirun");
}

class MpiRanks final : public Ranks {
 public:
  MpiRanks() : comm_(load_comm()) {
    if (comm_.init(&rank_, &size_) != 0)
      throw EnvironmentError("MPI_Init_thread failed: the MPI launcher and the system's Open MPI do not agree");
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  std::vector<std::string> all_gather(const std::string& mine) override {
    const int n = static_cast<int>(mine.size());
    std::vector<int> sizes(static_cast<size_t>(size_)), offsets(static_cast<size_t>(size_));
    comm_.all_gather_int(n, sizes.data());
    int total = 0;
    for (int r = 0; r < size_; ++r) {
      offsets[static_cast<size_t>(r)] = total;
      total += sizes[static_cast<size_t>(r)];
    }
    std::string all(static_cast<size_t>(total), '\0');
    comm_.all_gather_bytes(mine.data(), n, all.data(), sizes.data(), offsets.data());
    std::vector<std::string> out;
    for (int r = 0; r < size_; ++r)
      out.push_back(all.substr(static_cast<size_t>(offsets[static_cast<size_t>(r)]),
                               static_cast<size_t>(sizes[static_cast<size_t>(r)])));
    return out;
  }

 private:
  const mpi::Comm& comm_;
  int rank_ = 0, size_ = 1;
};

}  // namespace

std::unique_ptr<Ranks> single_rank() { return std::make_unique<SingleRank>(); }

Ranks* mpi_ranks() {
  if (!launched_by_mpi()) return nullptr;
  static MpiRanks ranks;
  return &ranks;
}

}  // namespace portalsim
