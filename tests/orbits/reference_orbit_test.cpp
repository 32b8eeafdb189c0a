// Orbits found by shooting on the exact solver and on the switching PIM (the method for large
// structures), checked by an independent integrator: the kink-located rkf78 at tolerance 1e-13
// (every step ends at a spring switch, so it keeps its order). Started on the orbit it must come
// back to it after k periods, and the Floquet multipliers from Richardson-extrapolated central
// differences of its flow (no tangent map at all) must be those of the exact tangent. Figure
// 4a's chain: the unstable period-1 orbit and the stable period-2 orbit the paper shows.
#include <catch2/catch.hpp>
#include <string>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

MethodSettings reference_method() {
  MethodSettings m;
  m.method = Method::rkf78;
  m.tolerance = 1e-13;
  m.locate_kinks = true;
  return m;
}

// `closure_tolerance`: how far rkf78 may carry the orbit from itself in k periods, the orbit's own
// method's error included.
void check_with_reference(StroboscopicMap& reference, const PeriodicOrbit& orbit,
                          const std::string& label, double closure_tolerance = 1e-10) {
  INFO(label);
  CHECK_FALSE(reference.exact_tangent());
  const double closure =
      (reference.advance(orbit.state, orbit.period) - orbit.state).lpNorm<Eigen::Infinity>();
  measured(label + ": |rkf78(y*) - y*|", closure);
  CHECK(closure <= closure_tolerance);
  // h = 1e-3: the O(h⁴) truncation (~1e-10 here) and rkf78's noise amplified by 1/h (~1e-10)
  // balance.
  const Matrix M = pwl::test::central_differences(reference, orbit.state, orbit.period, 1e-3, true);
  const double scale = std::max(1.0, orbit.monodromy.cwiseAbs().maxCoeff());
  const double monodromy = (M - orbit.monodromy).cwiseAbs().maxCoeff() / scale;
  const double multipliers =
      pwl::test::set_distance(floquet_multipliers(M).values, orbit.multipliers.values);
  measured(label + ": monodromy vs rkf78 differences", monodromy);
  measured(label + ": multipliers vs rkf78 differences", multipliers);
  CHECK(monodromy <= 2e-9);
  CHECK(multipliers <= 1e-9);
}

// Figure 4a's stable period-2 orbit and its unstable period-1 orbit, found by shooting on `map`
// from its Poincaré points after 500 periods, then checked against rkf78 (`label`: the method).
void check_figure_4a_orbits(StroboscopicMap& map, const std::string& label,
                            double closure_tolerance) {
  StroboscopicMap reference(analysis::PointCase(paper_five_dof_case("4a")), reference_method(), 1);
  const auto points = pwl::test::poincare_points(map, Vector::Zero(10), 500, 2);
  ShootingOptions options;
  options.tolerance = 1e-13;
  options.period = 2;
  const PeriodicOrbit two = find_periodic_orbit(map, points.back(), options);
  REQUIRE(two.residual <= 1e-12);
  check_with_reference(reference, two, label + "4a period-2", closure_tolerance);
  options.period = 1;
  const PeriodicOrbit one = find_periodic_orbit(map, 0.5 * (points[0] + points[1]), options);
  REQUIRE(one.residual <= 1e-12);
  CHECK(one.multipliers.largest_modulus() > 2);  // unstable: rkf78's error grows 2.2x per period
  check_with_reference(reference, one, label + "4a period-1", closure_tolerance);
}

}  // namespace

TEST_CASE("figure 4a's periodic orbits close under kink-located rkf78 at 1e-13", "[orbits]") {
  StroboscopicMap exact(analysis::PointCase(paper_five_dof_case("4a")),
                        MethodSettings{Method::exact}, 1);
  check_figure_4a_orbits(exact, "", 1e-10);
}

TEST_CASE("the switching PIM's periodic orbits close under kink-located rkf78 at 1e-13",
          "[orbits]") {
  // The method orbits of large structures are found with (above 20 masses): the higher-order PIM
  // with located switches, 200 steps a period, its exact tangent giving the monodromy. The same
  // two orbits of figure 4a, checked by the same independent integration. The PIM's own
  // truncation error over a period, not its Newton, sets how far rkf78 carries its orbits
  // (measured 1.5e-10 over the period-2 orbit's two periods): they must close to 1e-9.
  StroboscopicMap switching(analysis::PointCase(paper_five_dof_case("4a")),
                            MethodSettings{Method::pim_switching}, 200);
  REQUIRE(switching.exact_tangent());
  check_figure_4a_orbits(switching, "switching PIM, ", 1e-9);
}
