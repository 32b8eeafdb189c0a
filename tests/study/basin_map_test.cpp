// Basin maps (basin_map.hpp) against independent truth: the hardening gap oscillator at θ = 1.2,
// whose two coexisting period-1 orbits are the linear steady state (closed form) and a contacting
// orbit found by Newton on the exact event-driven solver's map; every sampled cell away from a basin
// boundary integrated out by the exact solver; the undamped resonance, unbounded from everywhere.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <map>

#include "orbit_cases.hpp"
#include "pwl/errors.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/basin_map.hpp"
#include "pwl/study/parameter_grid.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

std::map<long, PointResult> run(const BasinMapOptions& o, int threads) {
  std::string why;
  INFO(why);
  REQUIRE(o.is_valid(&why));
  std::map<long, PointResult> records;
  run_grid(
      o.tasks(), [&](long id) { return o.case_of(id); }, o.initial_state(0), o.settings(), {},
      [&](long id, const PointResult& r) { records.emplace(id, r); }, {threads});
  return records;
}

// The hardening oscillator of the continuation tests (one mass, α = 3, ζ = 0.1, Δ̃ = 1.5,
// Q = 0.5) at θ = 1.2, where a small linear orbit and a large contacting one coexist; initial
// states over (x1, v1) in [-4, 4]².
BasinMapOptions hardening_basins(int points) {
  BasinMapOptions o;
  o.chain = pwl::test::hardening_oscillator(1.2);
  o.first = {0, -4.0, 4.0, points};
  o.second = {1, -4.0, 4.0, points};
  o.point.transient_periods = 300;
  o.point.recorded_periods = 100;
  o.point.kept_points = 16;
  return o;
}

double distance(const Vector& a, const Vector& b) { return (a - b).norm(); }

}  // namespace

TEST_CASE("the basins of the hardening oscillator's two period-1 orbits", "[basin_map]") {
  const BasinMapOptions o = hardening_basins(15);
  const auto records = run(o, 2);
  REQUIRE(records.size() == 225);
  const BasinMap basins = match_basins(o, records);
  REQUIRE(basins.attractors.size() == 2);
  for (const Attractor& a : basins.attractors) CHECK(a.regime == "period-1");
  CHECK(basins.attractors[0].motions + basins.attractors[1].motions == 225);

  // The small orbit: the linear steady state x = Im(Q e^{iθt} / (1 − θ² + i ζ θ)) (the chain's
  // damping term is ζ x'), at t = 0: x = Q Im H, x' = Q θ Re H.
  const double theta = 1.2, q = 0.5, zeta = 0.1;
  const std::complex<double> H = 1.0 / std::complex<double>(1.0 - theta * theta, zeta * theta);
  Vector linear(2);
  linear << q * H.imag(), q * theta * H.real();
  // The large one: Newton on the exact solver's map, from the other attractor's point.
  const auto point_of = [](const Attractor& a) -> Vector { return a.points.bottomRows(1).transpose(); };
  const int small = distance(point_of(basins.attractors[0]), linear) <
                            distance(point_of(basins.attractors[1]), linear)
                        ? 0
                        : 1;
  const Attractor& small_orbit = basins.attractors[static_cast<std::size_t>(small)];
  const Attractor& large_orbit = basins.attractors[static_cast<std::size_t>(1 - small)];
  CHECK(distance(point_of(small_orbit), linear) <= 1e-8 * linear.norm());
  orbits::StroboscopicMap exact(PointCase(o.chain), MethodSettings{Method::exact}, 1);
  const orbits::PeriodicOrbit contacting = orbits::find_periodic_orbit(exact, point_of(large_orbit));
  CHECK(contacting.stable());
  CHECK(std::abs(contacting.state[0]) > 1.5);  // beyond the gap
  // The PIM's O(η²) error at 200 steps a period, on an orbit that switches twice a period.
  pwl::test::measured("contacting orbit: PIM against exact, relative",
                      distance(point_of(large_orbit), contacting.state) / contacting.state.norm());
  CHECK(distance(point_of(large_orbit), contacting.state) <= 1e-3 * contacting.state.norm());

  // Every third cell whose eight neighbours share its attractor (away from a basin boundary, where
  // the PIM's error could tip the motion either way), integrated out by the exact solver: it ends
  // nearer the orbit of its attractor.
  const auto attractor_at = [&](int i, int j) { return basins.attractor_of.at(i + 15L * j); };
  int checked = 0;
  for (int j = 1; j < 14; j += 3) {
    for (int i = 1; i < 14; i += 3) {
      bool interior = true;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) interior &= attractor_at(i + di, j + dj) == attractor_at(i, j);
      if (!interior) continue;
      const Vector end = exact.advance(o.initial_state(i + 15L * j), 400);
      const bool near_small =
          distance(end, linear) < distance(end, contacting.state);
      INFO("cell " << i << ", " << j);
      CHECK(attractor_at(i, j) == (near_small ? small_orbit.id : large_orbit.id));
      CHECK(std::min(distance(end, linear), distance(end, contacting.state)) < 1e-6);
      ++checked;
    }
  }
  CHECK(checked >= 10);
  // The orbits' own points lie in their basins (the small orbit's point is inside the grid).
  const int ci = static_cast<int>(std::lround((linear[0] + 4.0) / (8.0 / 14)));
  const int cj = static_cast<int>(std::lround((linear[1] + 4.0) / (8.0 / 14)));
  CHECK(attractor_at(ci, cj) == small_orbit.id);
}

TEST_CASE("a basin map does not depend on the number of threads", "[basin_map]") {
  const BasinMapOptions o = hardening_basins(6);
  const auto serial = run(o, 1);
  const auto parallel = run(o, 2);
  const BasinMap a = match_basins(o, serial), b = match_basins(o, parallel);
  CHECK(a.attractor_of == b.attractor_of);
  REQUIRE(a.attractors.size() == b.attractors.size());
  for (std::size_t k = 0; k < a.attractors.size(); ++k) {
    CHECK(a.attractors[k].points == b.attractors[k].points);  // bit for bit
    CHECK(a.attractors[k].first == b.attractors[k].first);
  }
}

TEST_CASE("the undamped resonance is unbounded from every initial state", "[basin_map]") {
  BasinMapOptions o;
  o.chain = pwl::test::undamped_resonance();
  o.first = {0, -1.0, 1.0, 3};
  o.second = {1, -1.0, 1.0, 3};
  o.point.transient_periods = 100;
  o.point.recorded_periods = 200;
  const BasinMap basins = match_basins(o, run(o, 2));
  REQUIRE(basins.attractors.size() == 1);
  CHECK(basins.attractors[0].name() == "unbounded");
  CHECK(basins.attractors[0].motions == 9);
}

TEST_CASE("a basin map refuses bad options, naming the field and the value", "[basin_map]") {
  const auto refused = [](const BasinMapOptions& o, const std::string& part) {
    std::string why;
    CHECK_FALSE(o.is_valid(&why));
    INFO(why);
    CHECK(why.find(part) != std::string::npos);
  };
  BasinMapOptions o = hardening_basins(5);
  o.first.component = 2;
  refused(o, "first axis: component 2 is out of range: the state has 2 components");
  o = hardening_basins(5);
  o.second.component = 0;
  refused(o, "both axes vary x1");
  o = hardening_basins(5);
  o.first.to = -5.0;
  refused(o, "first axis: range [-4, -5]");
  o = hardening_basins(5);
  o.point.kept_points = 101;
  refused(o, "kept points = 101 exceeds the recorded periods (100)");
  o.point.kept_points = 1;
  refused(o, "kept points = 1 must be at least 2");
  o = hardening_basins(5);
  o.point.section.phase = 0.5;
  refused(o, "give the strobe at phase 0");
  o = hardening_basins(5);
  o.base_state = Vector::Constant(3, 0.0);
  refused(o, "base state has 3 entries (finite: true), expected 2");
  o = hardening_basins(5);
  o.matching.cloud_factor = -1.0;
  refused(o, "cloud_factor = -1");
}
