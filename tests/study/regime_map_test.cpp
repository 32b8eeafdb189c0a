// Regime maps: ids, tasks and the classification of a small grid against sweeps of its rows.
#include <catch2/catch.hpp>

#include <map>

#include "pwl/study/regime_map.hpp"
#include "pwl/errors.hpp"

using namespace pwl;
using namespace pwl::analysis;

TEST_CASE("a regime map's grid, tasks and checks", "[regime_map]") {
  RegimeMapOptions o;
  o.first = {SweepParameter::theta, 1.0, 2.0, 3};
  o.second = {SweepParameter::alpha, 2.0, 4.0, 2};
  std::string why;
  REQUIRE(o.is_valid(&why));
  CHECK(o.cells() == 6);
  CHECK(o.tasks().size() == 6);
  o.mode = SweepMode::continuation;
  const auto rows = o.tasks();
  REQUIRE(rows.size() == 2);
  CHECK(rows[1].ids == std::vector<long>{3, 4, 5});
  const NondimensionalChain c = o.chain_of(5);
  CHECK(c.theta == 2.0);
  CHECK(c.alpha == std::vector<double>{4.0});
  o.second.parameter = SweepParameter::theta;
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("theta") != std::string::npos);
  o.second = {SweepParameter::alpha, 4.0, 2.0, 2};
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("reversed") != std::string::npos);
}

TEST_CASE("a map cell is the sweep point of the same parameters", "[regime_map]") {
  RegimeMapOptions o;
  o.chain = paper_five_dof_case("4a");
  o.first = {SweepParameter::theta, 0.9, 1.1, 3};
  o.second = {SweepParameter::alpha, 2.0, 3.0, 2};
  o.point.transient_periods = 150;
  o.point.recorded_periods = 100;
  std::map<long, PointResult> cells;
  run_grid(
      o.tasks(), [&](long id) { return o.chain_of(id); }, o.start_state(), o.point, {},
      [&](long id, const PointResult& r) { cells.emplace(id, r); }, {2});
  REQUIRE(cells.size() == 6);
  // Cell (θ = 1, α = 2) is figure 4a's case: period-2 (plots/README.md, checked against dopri5).
  CHECK(cells.at(1).regime == "period-2");
  CHECK(cells.at(1).lambda1 < 0.0);
  CHECK(cells.at(1).poincare.empty());
  const PointResult alone = evaluate_point(o.chain_of(4), o.start_state(), o.point);
  CHECK(alone.regime == cells.at(4).regime);
  CHECK(alone.final_state == cells.at(4).final_state);
}
