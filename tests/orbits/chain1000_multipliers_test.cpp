// The paper's 1000-mass chain followed by matrix-free continuation (no monodromy formed; the
// banded switching PIM's recorded tangent replayed for every GMRES and Arnoldi product), checked
// at a point of its branch against two independent truths:
//  - the leading multipliers against the eigenvalues of the 2000 x 2000 monodromy formed there
//    from all 2n tangent columns, to 1e-8;
//  - the orbit against another integrator: dopri5 at a tolerance of 1e-11 with every spring
//    switch located (the vector field's kinks) carries the orbit's state once round the forcing
//    period back to itself to 1e-7.
// (Release build only: about a minute there, most of it the dense eigenvalues.)
#include <catch2/catch.hpp>
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

  // The orbit closes under kink-located dopri5 at 1e-11.
  MethodSettings reference{Method::dopri5};
  reference.tolerance = 1e-11;
  reference.locate_kinks = true;
  StroboscopicMap dopri(analysis::PointCase(there), reference, 1);
  const double closure = (dopri.advance(p.orbit.state, 1) - p.orbit.state).lpNorm<Eigen::Infinity>();
  measured("1000 masses: |phi_T(y) - y| by kink-located dopri5 at 1e-11", closure);
  CHECK(closure <= 1e-7);
}
