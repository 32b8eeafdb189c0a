// The monodromy that shooting forms from the exact solver's tangent map, against central
// differences of the same solver's period map (its flow alone, no tangent), on orbits of the
// paper's 5-DOF chain: figure 4a's stable period-2 orbit and its unstable period-1 orbit
// (multiplier ≈ −2.25), and figure 5's unstable period-1 orbit (a complex pair just outside the
// unit circle). The flow is smooth near an orbit whose contacts are all transversal, so plain
// central differences converge at second order (a tenth of the step: a hundredth of the error)
// and their Richardson extrapolation at fourth.
#include <catch2/catch.hpp>
#include <string>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/orbit_profile.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::central_differences;
using pwl::test::measured;
using pwl::test::poincare_points;

namespace {

double max_abs(const Matrix& m) { return m.cwiseAbs().maxCoeff(); }

void check_against_differences(StroboscopicMap& map, const PeriodicOrbit& orbit,
                               const std::string& label) {
  INFO(label);
  REQUIRE(orbit.monodromy.rows() == map.state_size());
  // Every contact along the orbit is clear of grazing by more than the differences move it.
  const OrbitProfile profile = orbit_profile(map, orbit.state, orbit.period);
  REQUIRE(profile.max_gap.cwiseAbs().minCoeff() > 1e-2);
  REQUIRE(profile.min_gap.cwiseAbs().minCoeff() > 1e-2);

  const double scale = std::max(1.0, max_abs(orbit.monodromy));
  const double coarse =
      max_abs(central_differences(map, orbit.state, orbit.period, 1e-3, false) - orbit.monodromy) /
      scale;
  const double fine =
      max_abs(central_differences(map, orbit.state, orbit.period, 1e-4, false) - orbit.monodromy) /
      scale;
  const Matrix extrapolated = central_differences(map, orbit.state, orbit.period, 1e-3, true);
  const double richardson = max_abs(extrapolated - orbit.monodromy) / scale;
  measured(label + ": central differences h=1e-3", coarse);
  measured(label + ": central differences h=1e-4", fine);
  measured(label + ": Richardson h=1e-3", richardson);
  INFO("central differences off by " << coarse << " (h = 1e-3), " << fine
                                     << " (h = 1e-4); Richardson " << richardson);
  // Second order: the error of the differences, not of the tangent, dominates and shrinks 100x.
  CHECK(coarse / fine == Approx(100).epsilon(0.3));
  CHECK(richardson <= 1e-8);
  const double eigen =
      pwl::test::set_distance(floquet_multipliers(extrapolated).values, orbit.multipliers.values);
  measured(label + ": multipliers vs Richardson", eigen);
  CHECK(eigen <= 1e-8);
}

struct FigureOrbits {
  NondimensionalChain chain;
  StroboscopicMap map;
  std::vector<Vector> points;  // the attractor's Poincaré points
  explicit FigureOrbits(const std::string& figure)
      : chain(paper_five_dof_case(figure)),
        map(analysis::PointCase(chain), MethodSettings{Method::exact}, 1),
        points(poincare_points(map, Vector::Zero(10), 500, 100)) {}
  Vector mean(std::size_t last) const {
    Vector m = Vector::Zero(10);
    for (std::size_t i = points.size() - last; i < points.size(); ++i) m += points[i];
    return m / static_cast<double>(last);
  }
};

ShootingOptions period(int k) {
  ShootingOptions o;
  o.period = k;
  o.tolerance = 1e-13;
  return o;
}

}  // namespace

TEST_CASE("figure 4a's orbit monodromies equal central differences of the exact period map",
          "[orbits]") {
  FigureOrbits fig("4a");
  // The attractor is period-2: from its last point, Newton on the period-2 map.
  const PeriodicOrbit two = find_periodic_orbit(fig.map, fig.points.back(), period(2));
  CHECK(two.stable());
  CHECK((fig.map.advance(two.state, 1) - two.state).norm() > 0.1);  // not period-1
  check_against_differences(fig.map, two, "4a period-2");
  // Between its two points, the unstable period-1 orbit it doubled from.
  const PeriodicOrbit one = find_periodic_orbit(fig.map, fig.mean(2), period(1));
  REQUIRE(one.multipliers.values.size() == 10);
  CHECK(one.multipliers.values[0].real() == Approx(-2.2459).margin(1e-4));
  CHECK(one.multipliers.values[0].imag() == 0);
  CHECK(one.multipliers.unstable_count() == 1);
  check_against_differences(fig.map, one, "4a period-1");
}

TEST_CASE("figure 5's unstable period-1 orbit's monodromy equals central differences", "[orbits]") {
  FigureOrbits fig("5");
  // The motion winds round the orbit (a torus): the mean of its points is near it.
  const PeriodicOrbit one = find_periodic_orbit(fig.map, fig.mean(100), period(1));
  REQUIRE(one.multipliers.values.size() == 10);
  // A complex pair just outside the unit circle: a Neimark-Sacker torus.
  CHECK(std::abs(one.multipliers.values[0].imag()) > 0.5);
  CHECK(one.multipliers.largest_modulus() > 1.0);
  CHECK(one.multipliers.unstable_count() == 2);
  check_against_differences(fig.map, one, "5 period-1");
}
