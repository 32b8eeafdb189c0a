#pragma once
// Eigen's dense products kept on the calling thread while a SerialProducts lives. Private to
// pwl_core.
//
// Built with OpenMP, Eigen splits every product of more than about 50 000 multiply-adds over the
// threads. The banded constructions compute, one after another, the exponentials and force
// moments of substructures a few dozen degrees of freedom wide: each product lasts a few
// microseconds, so splitting it gains little, and between two products the idle threads spin
// (the OpenMP runtime's wait policy) instead of sleeping. On the 1000-mass chain that spin was
// about 10 ms of CPU time per construction, a quarter of the switching PIM's CPU time at its
// coarse steps, for about 1 ms of wall time. The guard sets the calling thread's OpenMP thread
// count (the nthreads-var of its task, which Eigen reads when it is not told otherwise) to one and
// restores it when it goes: other threads are not touched, and a region the guarded code opens
// with an explicit num_threads clause still spreads. The products' results are the same bits
// either way (Eigen splits a product by blocks of the result, not inside a sum).
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
  SerialProducts(const SerialProducts&) = delete;
  SerialProducts& operator=(const SerialProducts&) = delete;
  // The thread count the guarded code would have had.
  int saved_threads() const { return saved_; }

 private:
  int saved_;
  bool active_;
};

}  // namespace pwl::numerics_detail
