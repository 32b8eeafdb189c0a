// The paper's 1000-mass chain followed by matrix-free continuation (no monodromy formed; the
// banded switching PIM's recorded tangent replayed for every GMRES and Arnoldi product), checked
// at a point of its branch against two independent truths:
//  - the leading multipliers against the eigenvalues of the 2000 x 2000 monodromy formed there
//    from all 2n tangent columns, to 1e-8, and every eigenvalue of modulus above 1 − 1e-4 among
//    them (a margin asked of the leading multipliers, so that the band watched between two
//    points is not narrowed below it: eight of the long waves' crowd lie there, more than the six
//    a count alone would bring);
//  - the orbit against another integrator: dopri5 at a tolerance of 1e-11 with every spring
//    switch located (the vector field's kinks) carries the orbit's state once round the forcing
//    period back to itself to 1e-7.
// (Release build only: about 25 s there, most of it the dense eigenvalues.)
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "continuation_cases.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

TEST_CASE("the 1000-mass chain's branch: multipliers and closure against independent truth",
          "[orbits]") {
  const double from = 1.5;
  const NondimensionalChain chain = pwl::test::paper_chain(1000, from);
  const MethodSettings method{Method::pim_switching_banded};
  const Vector guess = pwl::test::settled_guess(chain, method, 200);
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = from;
  o.end = 1.6;
  o.method = method;
  o.steps_per_period = 200;
  o.max_points = 4;
  // Wider than continuation's default margin (1e-5), whose band here holds only the longest
  // wave's pair (|μ_k| ≈ 1 − 4e-6 k²), which six leading multipliers hold anyway.
  const double margin = 1e-4;
  REQUIRE(margin > kContinuationMargin);
  o.shooting.arnoldi.margin = margin;
  const ContinuationResult r =
      continue_periodic_orbit(analysis::PointModel(chain), guess, o);
  REQUIRE(r.matrix_free);
  REQUIRE(r.points.size() == 4);
  CHECK(r.monodromies == 0);
  const BranchPoint& p = r.points.back();
  REQUIRE(p.parameter > from);
  const NondimensionalChain there = pwl::test::paper_chain(1000, p.parameter);

  // Leading multipliers against the whole monodromy's eigenvalues.
  StroboscopicMap map(analysis::PointCase(there), method, 200);
  Matrix M;
  const Vector end = map.advance_with_jacobian(p.orbit.state, 1, M);
  CHECK((end - p.orbit.state).lpNorm<Eigen::Infinity>() <= 1e-9);
  const FloquetMultipliers all = floquet_multipliers(M);
  const auto& leading = p.orbit.multipliers.values;
  REQUIRE(leading.size() >= 6);
  const std::vector<std::complex<double>> expected(all.values.begin(),
                                                   all.values.begin() + leading.size());
  const double distance = pwl::test::set_distance(expected, leading);
  measured("1000 masses: leading multipliers against the monodromy's eigenvalues", distance);
  CHECK(distance <= 1e-8);
  CHECK(all.unstable_count() == p.orbit.multipliers.unstable_count());

  // The margin: every eigenvalue in the band |μ| > 1 − 1e-4 is among the reported, and the band
  // watched between the points was never narrowed below it.
  CHECK(p.orbit.multipliers.band_covered);
  CHECK(r.uncovered_bands == 0);
  std::size_t in_band = 0;
  const double band = pwl::test::farthest_in_band(all.values, leading, margin, &in_band);
  measured("1000 masses: eigenvalues in the band |mu| > 1 - 1e-4", static_cast<double>(in_band));
  measured("1000 masses: farthest of them from a reported multiplier", band);
  // More than the count: the margin, not the count, brought them.
  CHECK(in_band > static_cast<std::size_t>(o.shooting.arnoldi.count));
  CHECK(leading.size() >= in_band);
  CHECK(band <= 1e-8);
  REQUIRE(std::isfinite(r.narrowest_band));  // steps were checked
  CHECK(r.narrowest_band >= margin);

  // The orbit closes under kink-located dopri5 at 1e-11.
  MethodSettings reference{Method::dopri5};
  reference.tolerance = 1e-11;
  reference.locate_kinks = true;
  StroboscopicMap dopri(analysis::PointCase(there), reference, 1);
  const double closure = (dopri.advance(p.orbit.state, 1) - p.orbit.state).lpNorm<Eigen::Infinity>();
  measured("1000 masses: |phi_T(y) - y| by kink-located dopri5 at 1e-11", closure);
  CHECK(closure <= 1e-7);
}
