// Construction from the period (lib/src/banded/periodic_cut.hpp) where the substructures are
// large: wide windows are where Eigen would split an exponential's products over the threads if
// asked outside a parallel region, and where the rounding of a substructure then depends on which
// other blocks share its chunk of the assembly (one of 256 blocks in the long chain's last chunk,
// several in the short chain's only chunk). The banded exponential keeps every substructure's
// products on one thread (inside a parallel region over the substructures, or, where they are too
// few to pay for one, on the calling thread with Eigen told so: serial_products.hpp), so the long
// chain's laid-out operators are still those built row by row, bit for bit, on two threads.
// Release only: the row-by-row build of 4000 masses with 180-mass substructures takes seconds.
#include <omp.h>

#include <catch2/catch.hpp>

#include "pwl/integrators/banded_step_operators.hpp"
#include "pwl/model/chain_builders.hpp"
#include "step_operator_bits.hpp"

using namespace pwl;

TEST_CASE("construction from the period: wide substructures on two threads, bit for bit",
          "[banded][period][threads]") {
  const int n = 4000;
  ChainParameters p;
  p.masses = n;
  p.mass.resize(n);
  for (int i = 0; i < n; ++i) p.mass[static_cast<std::size_t>(i)] = 1.0 + 0.1 * (i % 4);
  p.k1 = {25.0};
  p.damping = {0.2};
  p.k2 = {0.3};
  p.gap = {0.0};
  for (int i = 0; i < n; i += 2) p.loads.push_back({i, 1.0, 3.0, 0.0});
  const GapStructure s = make_chain(p);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(2);
  BandedExponentialOptions band;
  const BandedStepOperators a = make_banded_step_operators(s, 13.0, band);
  band.from_period = false;
  const BandedStepOperators b = make_banded_step_operators(s, 13.0, band);
  omp_set_num_threads(threads);
  INFO("band " << a.truncation.band << ", margin " << a.truncation.margin << ", laid out "
               << a.truncation.laid_out);
  CHECK(a.truncation.cell_dofs == 4);
  CHECK(a.truncation.margin > 75);  // substructures of more than 150 masses
  CHECK(a.truncation.laid_out >= n / 4);
  pwl::test::check_same_step_operators(a, b);
}
