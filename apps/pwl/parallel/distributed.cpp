#include "parallel/distributed.hpp"

#include <cstdlib>

#ifdef PWL_HAVE_MPI
#include <mpi.h>
#endif

namespace pwl::app {

namespace {

// Set by Open MPI's mpirun (OMPI_*), by PMIx launchers (PMIX_RANK) and by Hydra/Slurm (PMI_*).
bool launched_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"}) {
    if (std::getenv(name) != nullptr) return true;
  }
  return false;
}

}  // namespace

Distributed::Distributed() {
#ifdef PWL_HAVE_MPI
  int already = 0;
  MPI_Initialized(&already);
  if (!already && launched_by_mpirun()) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    initialised_ = true;
  }
  if (initialised_ || already) {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
#else
  (void)launched_by_mpirun;
#endif
}

Distributed::~Distributed() {
#ifdef PWL_HAVE_MPI
  if (initialised_) MPI_Finalize();
#endif
}

void Distributed::barrier() const {
#ifdef PWL_HAVE_MPI
  if (size_ > 1) MPI_Barrier(MPI_COMM_WORLD);
#endif
}

std::vector<std::string> Distributed::gather(const std::string& local) const {
  if (size_ == 1) return {local};
#ifdef PWL_HAVE_MPI
  // Lengths first, then the bytes; strings of more than 2 GB are not expected from summaries.
  const int length = static_cast<int>(local.size());
  std::vector<int> lengths(static_cast<std::size_t>(size_), 0);
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::vector<int> offsets(static_cast<std::size_t>(size_), 0);
  int total = 0;
  for (int r = 0; r < size_; ++r) {
    offsets[static_cast<std::size_t>(r)] = total;
    total += lengths[static_cast<std::size_t>(r)];
  }
  std::string all(static_cast<std::size_t>(rank_ == 0 ? total : 0), '\0');
  MPI_Gatherv(local.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
              0, MPI_COMM_WORLD);
  std::vector<std::string> result;
  if (rank_ == 0) {
    for (int r = 0; r < size_; ++r) {
      result.push_back(all.substr(static_cast<std::size_t>(offsets[static_cast<std::size_t>(r)]),
                                  static_cast<std::size_t>(lengths[static_cast<std::size_t>(r)])));
    }
  }
  return result;
#else
  return {local};
#endif
}

void Distributed::abort(int code) const {
#ifdef PWL_HAVE_MPI
  if (size_ > 1) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

}  // namespace pwl::app
