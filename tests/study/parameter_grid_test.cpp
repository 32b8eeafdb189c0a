// The grid runner's stop request: a grid stops between points and inside a point (between its
// forcing periods) on every thread, keeps what reached the sink, and a grid resumed from those
// points ends with the results of one never stopped. A sink that throws stops the other threads
// the same way.
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <map>
#include <stdexcept>
#include <thread>

#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/parameter_sweep.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// x'' + ζ x' + x + α max(0, x - Δ̃) = Q sin θτ swept in θ by continuation, up and down: two
// tasks of 25 points, each point starting from the one before.
SweepOptions oscillator_sweep() {
  SweepOptions o;
  o.chain.masses = 1;
  o.chain.alpha = {3.0};
  o.chain.zeta = 0.1;
  o.chain.gap = {1.5};
  o.chain.amplitude = {0.5};
  o.parameter = SweepParameter::theta;
  o.from = 0.8;
  o.to = 2.0;
  o.points = 25;
  o.mode = SweepMode::continuation;
  o.point.transient_periods = 200;
  o.point.recorded_periods = 20;
  o.point.components = {0, 1};
  o.point.lyapunov = false;
  return o;
}

GridEnd run(const SweepOptions& o, const std::map<long, PointResult>& done,
            std::map<long, PointResult>& sunk, const GridRun& grid) {
  return run_grid(
      o.tasks(), [&](long id) { return o.case_of(id); }, o.start_state(), o.point, done,
      [&](long id, const PointResult& r) { sunk.emplace(id, r); }, grid);
}

void require_same(const std::map<long, PointResult>& a, const std::map<long, PointResult>& b) {
  REQUIRE(a.size() == b.size());
  for (const auto& [id, r] : a) {
    INFO("point " << id);
    const PointResult& s = b.at(id);
    CHECK(r.regime == s.regime);
    CHECK(r.period == s.period);
    CHECK(r.poincare == s.poincare);
    CHECK(r.final_state == s.final_state);
  }
}

}  // namespace

TEST_CASE("a stopped grid keeps the finished points, and resumed it ends as an unstopped one",
          "[parameter_grid]") {
  const SweepOptions o = oscillator_sweep();
  std::map<long, PointResult> whole;
  REQUIRE(run(o, {}, whole, {1}) == GridEnd::finished);
  REQUIRE(whole.size() == 50);

  for (int threads : {1, 2}) {
    INFO(threads << " threads");
    // Asked to stop once 7 points have reached the sink.
    std::map<long, PointResult> first;
    std::atomic<int> sunk{0};
    GridRun grid{threads};
    grid.stop = [&] { return sunk.load() >= 7; };
    REQUIRE(run_grid(
                o.tasks(), [&](long id) { return o.case_of(id); }, o.start_state(), o.point, {},
                [&](long id, const PointResult& r) {
                  first.emplace(id, r);
                  ++sunk;
                },
                grid) == GridEnd::stopped);
    // One thread stops at its next check; with two, the other thread's point may already be
    // waiting at the sink.
    CHECK(first.size() >= 7);
    CHECK(first.size() <= static_cast<std::size_t>(6 + threads));
    for (const auto& [id, r] : first) {
      INFO("point " << id);
      CHECK(r.poincare == whole.at(id).poincare);
    }
    // Resumed from them: only the others are computed, and every result is the unstopped one's.
    std::map<long, PointResult> rest;
    REQUIRE(run(o, first, rest, {threads}) == GridEnd::finished);
    CHECK(rest.size() == 50 - first.size());
    for (const auto& [id, r] : rest) CHECK(first.count(id) == 0);
    rest.insert(first.begin(), first.end());
    require_same(rest, whole);
  }
}

TEST_CASE("a stop inside a long point leaves it within one forcing period", "[parameter_grid]") {
  SweepOptions o = oscillator_sweep();
  o.points = 1;
  o.downward = false;
  o.point.transient_periods = 100000000;  // hours of integration if nothing stopped it
  std::map<long, PointResult> sunk;
  std::atomic<long> asked{0};
  GridRun grid{1};
  // Yes from the 500th question on: the point is asked once before it starts and then once per
  // forcing period, so it stops after 498 periods, asked no more.
  grid.stop = [&] { return ++asked >= 500; };
  const auto start = std::chrono::steady_clock::now();
  CHECK(run(o, {}, sunk, grid) == GridEnd::stopped);
  CHECK(sunk.empty());
  CHECK(asked.load() == 500);
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(60));
}

TEST_CASE("a point that fails stops the other threads inside their points", "[parameter_grid]") {
  // Two independent points on two threads: point 0 is long; point 1 fails at once (its case is
  // refused, as bad input is). The thread on point 0 leaves it at its next forcing period, and
  // the failure comes out of the grid. (A sink that throws, say a journal on a full disk, goes
  // the same way: tests/cli/faults.cmake runs that end to end.)
  SweepOptions o = oscillator_sweep();
  o.mode = SweepMode::independent;
  o.points = 2;
  o.downward = false;
  o.point.transient_periods = 100000000;  // hours of integration if nothing stopped it
  const std::vector<GridTask> tasks = o.tasks();
  REQUIRE(tasks.size() == 2);
  const auto start = std::chrono::steady_clock::now();
  const auto case_of = [&](long id) -> PointCase {
    if (id == 1) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));  // point 0 is under way
      throw std::invalid_argument("point 1 is refused");
    }
    return o.case_of(id);
  };
  CHECK_THROWS_WITH(run_grid(tasks, case_of, o.start_state(), o.point, {},
                             [](long, const PointResult&) {}, {2}),
                    "point 1 is refused");
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(60));
}
