#pragma once
// The processes of a distributed run: MPI when the program was built with it (PWL_HAVE_MPI) and
// started by mpirun, otherwise one process. Only what a parameter study needs: the rank and
// count, a barrier, gathering strings on rank 0, and aborting every process at once.
#include <string>
#include <vector>

namespace pwl::app {

class Distributed {
 public:
  // Initialises MPI (threads funnelled: OpenMP threads never call MPI) when it is available and
  // the launcher set up a world of processes; does nothing otherwise.
  Distributed();
  ~Distributed();  // finalises MPI if it was initialised here
  Distributed(const Distributed&) = delete;
  Distributed& operator=(const Distributed&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  void barrier() const;
  // Rank 0 receives every rank's string, in rank order (its own first); other ranks get nothing.
  std::vector<std::string> gather(const std::string& local) const;
  // Ends every process with `code` (MPI_Abort); in a single process, std::exit.
  [[noreturn]] void abort(int code) const;

 private:
  int rank_ = 0;
  int size_ = 1;
  bool initialised_ = false;
};

}  // namespace pwl::app
