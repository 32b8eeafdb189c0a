// Multiple shooting (the k periods cut into m arcs, Newton on all arc starts at once) must find the
// same orbit and the same multipliers as single shooting, with the exact solver (arcs anywhere)
// and with the PIM (arcs on its step grid); and on a repelling orbit inside figure 6's chaotic
// attractor it converges from guesses where single shooting does not.
#include <algorithm>
#include <catch2/catch.hpp>
#include <optional>
#include <string>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

ShootingOptions shooting(int period, int shots) {
  ShootingOptions o;
  o.period = period;
  o.shots = shots;
  o.tolerance = 1e-12;
  return o;
}

void check_same(const PeriodicOrbit& single, const PeriodicOrbit& multiple,
                const std::string& label) {
  INFO(label);
  const double state = (single.state - multiple.state).lpNorm<Eigen::Infinity>();
  const double monodromy = (single.monodromy - multiple.monodromy).cwiseAbs().maxCoeff();
  const double multipliers =
      pwl::test::set_distance(single.multipliers.values, multiple.multipliers.values);
  measured(label + ": state", state);
  measured(label + ": monodromy", monodromy);
  measured(label + ": iterations (single, multiple)",
           single.iterations + 0.001 * multiple.iterations);
  CHECK(multiple.iterations >= 2);
  CHECK(state <= 1e-10);
  CHECK(monodromy <= 1e-9 * std::max(1.0, single.monodromy.cwiseAbs().maxCoeff()));
  CHECK(multipliers <= 1e-9);
  CHECK(multiple.residual <= 1e-12 * std::max(1.0, multiple.state.lpNorm<Eigen::Infinity>()));
}

}  // namespace

TEST_CASE("multiple shooting finds the orbit single shooting finds", "[orbits]") {
  const NondimensionalChain chain = paper_five_dof_case("4a");
  SECTION("exact solver: one arc per period, and two") {
    StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::exact}, 1);
    // Ten periods from rest: still far from the attractor, so Newton has work to do.
    const Vector seed = pwl::test::poincare_points(map, Vector::Zero(10), 9, 1).back();
    const PeriodicOrbit single = find_periodic_orbit(map, seed, shooting(2, 1));
    CHECK(single.iterations >= 3);
    check_same(single, find_periodic_orbit(map, seed, shooting(2, 2)), "4a period-2, 2 shots");
    check_same(single, find_periodic_orbit(map, seed, shooting(2, 4)), "4a period-2, 4 shots");
    // The unstable period-1 orbit, in three arcs of T/3.
    const Vector between = 0.5 * (seed + map.advance(seed, 1));
    check_same(find_periodic_orbit(map, between, shooting(1, 1)),
               find_periodic_orbit(map, between, shooting(1, 3)), "4a period-1, 3 shots");
  }
  SECTION("PIM: arcs of 100 of its 400 steps") {
    StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::pim}, 200);
    const Vector seed = pwl::test::poincare_points(map, Vector::Zero(10), 9, 1).back();
    check_same(find_periodic_orbit(map, seed, shooting(2, 1)),
               find_periodic_orbit(map, seed, shooting(2, 4)), "PIM 4a period-2, 4 shots");
  }
}

TEST_CASE(
    "multiple shooting reaches a repelling period-2 orbit from guesses single shooting misses",
    "[orbits]") {
  const NondimensionalChain chain = paper_five_dof_case("6");
  StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::exact}, 1);
  const std::vector<Vector> points = pwl::test::poincare_points(map, Vector::Zero(10), 500, 200);
  // A period-2 orbit of the chaotic attractor: Newton from its closest period-2 returns, the
  // first that is not the period-1 orbit.
  std::vector<std::pair<double, std::size_t>> returns;
  for (std::size_t i = 0; i + 2 < points.size(); ++i)
    returns.emplace_back((points[i + 2] - points[i]).norm(), i);
  std::sort(returns.begin(), returns.end());
  std::optional<PeriodicOrbit> orbit;
  for (const auto& [distance, i] : returns) {
    try {
      PeriodicOrbit o = find_periodic_orbit(map, points[i], shooting(2, 1));
      if ((map.advance(o.state, 1) - o.state).norm() > 1e-3) {
        orbit = std::move(o);
        break;
      }
    } catch (const Error&) {  // no orbit from here
    }
  }
  REQUIRE(orbit.has_value());
  CHECK(orbit->multipliers.largest_modulus() > 2);
  // Guesses ±0.2, ±0.4 and ±0.8 off along each axis; "reached": converged to this orbit.
  int single_only = 0, multiple_only = 0, both = 0;
  for (Index j = 0; j < 10; ++j) {
    for (double delta : {0.2, -0.2, 0.4, -0.4, 0.8, -0.8}) {
      Vector guess = orbit->state;
      guess(j) += delta;
      const auto reaches = [&](int shots) {
        try {
          return (find_periodic_orbit(map, guess, shooting(2, shots)).state - orbit->state).norm() <
                 1e-8;
        } catch (const Error&) {  // no orbit from here
          return false;
        }
      };
      const bool single = reaches(1), multiple = reaches(4);
      single_only += single && !multiple;
      multiple_only += multiple && !single;
      both += single && multiple;
    }
  }
  measured("guesses reached by single shooting only", single_only);
  measured("guesses reached by multiple shooting only", multiple_only);
  measured("guesses reached by both", both);
  CHECK(multiple_only >= 1);
  CHECK(both >= 1);
}
