// Unstable periodic orbits inside a chaotic attractor: figure 6's case of the paper's 5-DOF chain
// (α = 15, θ = 1.5; chaotic by the exact solver: λ1 ≈ 0.33 per period, K ≈ 1; the paper and
// SPEC §5 call it quasi-periodic). Newton is seeded from the recorded Poincaré point that moves
// least in one period (for period 2: the closest returns in two periods, nearest first), as in
// the recurrence method of D. Auerbach et al., Phys. Rev. Lett. 58 (1987) 2387, and must converge
// although the orbit repels; the motion itself visits it only in passing.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

// The recorded point i with the smallest |P_{i+k} − P_i|.
std::size_t closest_return(const std::vector<Vector>& points, std::size_t k) {
  std::size_t best = 0;
  for (std::size_t i = 0; i + k < points.size(); ++i) {
    if ((points[i + k] - points[i]).norm() < (points[best + k] - points[best]).norm()) best = i;
  }
  return best;
}

}  // namespace

TEST_CASE("unstable periodic orbits are found inside figure 6's chaotic attractor", "[orbits]") {
  const NondimensionalChain chain = paper_five_dof_case("6");
  // The motion is chaotic: the study pipeline's classification on the exact solver.
  analysis::PointSettings settings;
  settings.transient_periods = 500;
  settings.recorded_periods = 300;
  settings.method = MethodSettings{Method::exact};
  settings.lyapunov_estimate = analysis::LyapunovEstimate::two_trajectories;
  const analysis::PointResult classified =
      analysis::evaluate_point(analysis::PointCase(chain), Vector::Zero(10), settings);
  measured("figure 6 lambda1", classified.lambda1);
  REQUIRE(classified.regime == "chaotic");
  REQUIRE(classified.lambda1 > 0.1);

  StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::exact}, 1);
  const std::vector<Vector> points = pwl::test::poincare_points(map, Vector::Zero(10), 500, 300);

  SECTION("period 1, by single and by multiple shooting") {
    const Vector seed = points[closest_return(points, 1)];
    ShootingOptions options;
    options.tolerance = 1e-12;
    const PeriodicOrbit orbit = find_periodic_orbit(map, seed, options);
    measured("chaotic saddle period-1 residual", orbit.residual);
    measured("chaotic saddle period-1 |mu|", orbit.multipliers.largest_modulus());
    CHECK(orbit.residual <= 1e-10);
    CHECK((map.advance(orbit.state, 1) - orbit.state).lpNorm<Eigen::Infinity>() <= 1e-10);
    // A saddle: one real multiplier beyond −1 (≈ −3.02), the rest inside.
    CHECK(orbit.multipliers.largest_modulus() > 1.5);
    CHECK(orbit.multipliers.values[0].real() < -1.5);
    CHECK(orbit.multipliers.unstable_count() == 1);
    options.shots = 2;  // half a period per arc
    const PeriodicOrbit twice = find_periodic_orbit(map, seed, options);
    CHECK((twice.state - orbit.state).lpNorm<Eigen::Infinity>() <= 1e-10);

    // The motion does not stay on it: most recorded points are far from it ...
    const double size = [&] {
      double s = 0;
      for (const Vector& p : points) s = std::max(s, (p - points.front()).norm());
      return s;
    }();
    const auto near = std::count_if(points.begin(), points.end(), [&](const Vector& p) {
      return (p - orbit.state).norm() < 0.05 * size;
    });
    measured("fraction of points within 5% of the saddle", near / 300.0);
    CHECK(near < 30);
    // ... and a start 1e-10 off it leaves (beyond 1e-2) after about log(1e8) / log|μ| periods.
    const double expected = std::log(1e8) / std::log(orbit.multipliers.largest_modulus());
    Vector y = orbit.state;
    y(0) += 1e-10;
    int left = 0;
    for (int k = 1; k <= 100 && left == 0; ++k) {
      y = map.advance(y, 1);
      if ((y - orbit.state).norm() > 1e-2) left = k;
    }
    measured("periods to leave the saddle", left);
    measured("periods expected from |mu|", expected);
    CHECK(left > 0.5 * expected);
    CHECK(left < 1.5 * expected);
  }

  SECTION("period 2, by multiple shooting") {
    // The closest period-2 returns, nearest first, until one leads to a period-2 orbit that is not
    // the period-1 orbit run twice (a close return may be a visit to the period-1 saddle).
    std::vector<std::pair<double, std::size_t>> returns;
    for (std::size_t i = 0; i + 2 < points.size(); ++i) {
      returns.emplace_back((points[i + 2] - points[i]).norm(), i);
    }
    std::sort(returns.begin(), returns.end());
    ShootingOptions options;
    options.tolerance = 1e-12;
    options.period = 2;
    options.shots = 2;
    std::optional<PeriodicOrbit> orbit;
    int tried = 0;
    for (const auto& [distance, i] : returns) {
      if (++tried > 10) break;
      try {
        PeriodicOrbit o = find_periodic_orbit(map, points[i], options);
        if ((map.advance(o.state, 1) - o.state).norm() > 0.1) {
          orbit = std::move(o);
          break;
        }
      } catch (const Error&) {  // no orbit from here
      }
    }
    measured("closest returns tried for a period-2 orbit", tried);
    REQUIRE(orbit.has_value());
    measured("chaotic saddle period-2 residual", orbit->residual);
    measured("chaotic saddle period-2 |mu|", orbit->multipliers.largest_modulus());
    CHECK(orbit->residual <= 1e-10);
    CHECK((map.advance(orbit->state, 2) - orbit->state).lpNorm<Eigen::Infinity>() <= 1e-10);
    CHECK(orbit->multipliers.largest_modulus() > 1.5);
  }
}
