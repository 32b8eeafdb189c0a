#pragma once
// When the products of long chains go parallel: rows split into one contiguous block per OpenMP
// thread, from 10^5 rows on (a chain of 5·10^4 masses and more: T's 2n rows, the n rows of K, C
// and the springs). Each row's sum is computed as on one thread, so the results do not depend on
// the thread count. Inside a parallel region (a sweep spreading its points over the threads) a
// product stays on its thread. Private to pwl_core.
#include <omp.h>

#include "pwl/types.hpp"

namespace pwl::numerics_detail {

inline constexpr Index kParallelRows = 100000;

// True when work over `rows` rows should be spread over the threads.
inline bool spread_rows(Index rows) {
  return rows >= kParallelRows && omp_get_max_threads() > 1 && !omp_in_parallel();
}

// block(begin, end) over [r0, r1): once on this thread, or once per thread on its own block.
template <class Block>
void over_row_blocks(Index r0, Index r1, Block&& block) {
  if (!spread_rows(r1 - r0)) {
    block(r0, r1);
    return;
  }
#pragma omp parallel
  {
    const Index t = omp_get_thread_num(), count = omp_get_num_threads();
    const Index rows = r1 - r0;
    block(r0 + rows * t / count, r0 + rows * (t + 1) / count);
  }
}

}  // namespace pwl::numerics_detail
