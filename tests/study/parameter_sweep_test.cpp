// Parameter sweeps: input checks, results that do not depend on the number of threads, and a
// continuation that shows the two coexisting branches of a hardening gap oscillator.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>

#include "pwl/study/parameter_sweep.hpp"
#include "pwl/errors.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

std::map<long, PointResult> run(const SweepOptions& o, int threads) {
  std::map<long, PointResult> records;
  run_grid(
      o.tasks(), [&](long id) { return o.chain_of(id); }, o.start_state(), o.point, {},
      [&](long id, const PointResult& r) { records.emplace(id, r); }, {threads});
  return records;
}

// x'' + ζ x' + x + α max(0, x - Δ̃) = Q sin θτ: one mass, one gap spring.
SweepOptions single_gap_oscillator() {
  SweepOptions o;
  o.chain.masses = 1;
  o.chain.alpha = {3.0};
  o.chain.zeta = 0.1;
  o.chain.gap = {1.5};
  o.chain.amplitude = {0.5};
  o.parameter = SweepParameter::theta;
  o.from = 0.8;
  o.to = 2.0;
  o.points = 25;  // θ step 0.05
  o.mode = SweepMode::continuation;
  o.point.transient_periods = 300;
  o.point.recorded_periods = 20;
  o.point.components = {0, 1};
  o.point.lyapunov = false;
  return o;
}

}  // namespace

TEST_CASE("bad sweep input is refused with the field named", "[parameter_sweep]") {
  SweepOptions o;
  std::string why;
  REQUIRE(o.is_valid(&why));
  o.points = 0;
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("points = 0") != std::string::npos);
  o.points = 10;
  o.from = 3.0;
  o.to = 0.5;
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("reversed") != std::string::npos);
  o.from = -1.0;
  o.to = 1.0;
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("theta") != std::string::npos);
  o.from = 0.5;
  o.point.components = {10};
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("component 10") != std::string::npos);
  CHECK_THROWS_AS(parse_sweep_parameter("omega"), InputError);
  CHECK(parse_sweep_parameter("delta") == SweepParameter::gap);
}

TEST_CASE("the values, ids and tasks of a sweep", "[parameter_sweep]") {
  SweepOptions o;
  o.from = 1.0;
  o.to = 2.0;
  o.points = 5;
  CHECK(o.value(0) == 1.0);
  CHECK(o.value(4) == 2.0);
  CHECK(o.value(2) == 1.5);
  CHECK(o.tasks().size() == 5);
  o.mode = SweepMode::continuation;
  const auto tasks = o.tasks();
  REQUIRE(tasks.size() == 2);
  CHECK(tasks[0].ids == std::vector<long>{0, 1, 2, 3, 4});
  CHECK(tasks[1].ids == std::vector<long>{9, 8, 7, 6, 5});
  CHECK(o.chain_of(6).theta == 1.25);
  CHECK(with_parameter(o.chain, SweepParameter::amplitude, 2.0).amplitude[1] == -2.0);
}

TEST_CASE("one thread and two threads give identical results", "[parameter_sweep]") {
  SweepOptions o;
  o.chain = paper_five_dof_case("5");
  o.from = 0.8;
  o.to = 2.6;
  o.points = 6;
  o.point.transient_periods = 20;
  o.point.recorded_periods = 100;
  o.point.components = {4, 9};
  for (SweepMode mode : {SweepMode::independent, SweepMode::continuation}) {
    o.mode = mode;
    const auto serial = run(o, 1);
    const auto parallel = run(o, 2);
    REQUIRE(serial.size() == parallel.size());
    for (const auto& [id, r] : serial) {
      const PointResult& p = parallel.at(id);
      CHECK(r.regime == p.regime);
      CHECK(r.poincare == p.poincare);  // bit for bit
      CHECK(r.final_state == p.final_state);
      CHECK(std::isnan(r.lambda1) == std::isnan(p.lambda1));
      if (!std::isnan(r.lambda1)) CHECK(r.lambda1 == p.lambda1);
      if (!std::isnan(r.K)) CHECK(r.K == p.K);
    }
  }
}

TEST_CASE("a continuation across the hysteresis of a gap oscillator shows both branches",
          "[parameter_sweep]") {
  // A hardening oscillator: once the mass reaches the gap the resonance bends to higher θ. Sweeping
  // upward the motion stays on the large, contacting branch past the linear resonance; sweeping
  // downward it stays on the small branch that never reaches the gap, which is the linear
  // oscillator's steady state, amplitude Q / sqrt((1 - θ²)² + (ζθ)²), exactly.
  const SweepOptions o = single_gap_oscillator();
  const auto records = run(o, 2);
  REQUIRE(records.size() == 50);
  auto amplitude = [&](long id) {
    const PointResult& r = records.at(id);
    const double theta = o.value(static_cast<int>(id % o.points));
    const double x = r.poincare[r.poincare.size() - 2], v = r.poincare.back();
    return std::sqrt(x * x + v * v / (theta * theta));
  };
  auto linear = [&](double theta) {
    return 0.5 / std::sqrt(std::pow(1 - theta * theta, 2) + std::pow(0.1 * theta, 2));
  };
  int coexisting = 0;
  for (int i = 0; i < o.points; ++i) {
    const double theta = o.value(i);
    CHECK(records.at(i).regime == "period-1");
    CHECK(records.at(o.points + i).regime == "period-1");
    const double up = amplitude(i), down = amplitude(o.points + i);
    if (up > 1.5 && down < 1.5) {
      ++coexisting;
      // The small branch is the linear steady state; the large one is well beyond the gap.
      CHECK(down == Approx(linear(theta)).epsilon(1e-8));
      CHECK(up > 2.0 * down);
    }
  }
  // θ = 1.15 and 1.2 (the region widens with a finer grid): two attractors.
  CHECK(coexisting >= 2);
  // Away from the resonance both directions find the same, linear, motion.
  for (int i : {20, 24}) {
    CHECK(amplitude(i) == Approx(linear(o.value(i))).epsilon(1e-8));
    CHECK(amplitude(o.points + i) == Approx(linear(o.value(i))).epsilon(1e-8));
  }
}
