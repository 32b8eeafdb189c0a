#pragma once
// Eigen's dense products kept on the calling thread while a SerialProducts lives. Private to
// pwl_core.
//
// Built with OpenMP, Eigen splits a product over the threads from about 10^5 multiply-adds on
// (one thread per 50 000), unless it runs inside a team of more than one thread. The banded
// constructions compute, one after another, the exponentials and force moments of substructures a
// few dozen degrees of freedom wide: each product lasts microseconds, so splitting it gains
// little, and between two products the idle threads spin (the OpenMP runtime's wait policy)
// instead of sleeping. On the 1000-mass chain that spin was 8 to 12 ms of CPU time per
// construction, a quarter of the switching PIM's CPU time at its coarse steps, for about 1 ms of
// wall time. The guard sets the first entry of the calling task's OpenMP thread count (the
// nthreads-var that Eigen reads through omp_get_max_threads) to one and restores it when it goes:
// other threads are not touched. A region opened inside the guard hands its tasks the next entry
// of an OMP_NUM_THREADS list (2,2 gives them two again), so code that opens one puts a guard in
// its body too. A caller's Eigen::setNbThreads overrides the guard; pwl never calls it. Below the
// rows the guard is used for (kSerialProductRows), a product split over two threads gives the same
// bits as on one; from about 320 rows Eigen's depth blocks change with the thread count, and so do
// the bits.
#include <omp.h>

namespace pwl::numerics_detail {

// Below this many rows a dense product is not worth splitting here: a 128 x 128 product is about
// 2·10^6 multiply-adds, a few hundred microseconds, against the threads' spin after a region.
inline constexpr long kSerialProductRows = 128;

class SerialProducts {
 public:
  // active false: nothing changes (Eigen splits as it sees fit).
  explicit SerialProducts(bool active = true) : saved_(omp_get_max_threads()), active_(active) {
    if (active_) omp_set_num_threads(1);
  }
  ~SerialProducts() {
    if (active_) omp_set_num_threads(saved_);
  }
  // Active for products of fewer than kSerialProductRows rows, the policy in one place.
  static SerialProducts for_rows(long rows) { return SerialProducts(rows < kSerialProductRows); }
  SerialProducts(const SerialProducts&) = delete;
  SerialProducts& operator=(const SerialProducts&) = delete;

 private:
  int saved_;
  bool active_;
};

}  // namespace pwl::numerics_detail
