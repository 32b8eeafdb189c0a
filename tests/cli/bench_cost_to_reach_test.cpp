// The work-precision chart's cost-to-reach comparison (pwl bench accuracy): the cheapest point at
// or below an error, and the comparison of two families over a range of errors, on curves whose
// answer is known by hand.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "bench/accuracy_bench.hpp"
#include "pwl/errors.hpp"

using pwl::app::accuracy_detail::cheapest_reaching;
using pwl::app::accuracy_detail::compare_cost_to_reach;
using pwl::app::accuracy_detail::WorkCurve;

TEST_CASE("cost to reach: the cheapest point at or below an error, over every curve") {
  const std::vector<WorkCurve> family{{{1.0, 1e-2}, {2.0, 1e-5}, {4.0, 1e-9}},
                                      {{0.5, 1e-2}, {1.5, 1e-4}, {9.0, 1e-12}}};
  auto p = cheapest_reaching(family, 1e-2);
  CHECK(p.curve == 1);
  CHECK(p.point == 0);
  CHECK(p.seconds == 0.5);
  p = cheapest_reaching(family, 5e-3);  // between points: the next one down
  CHECK(p.curve == 1);
  CHECK(p.point == 1);
  p = cheapest_reaching(family, 1e-5);  // at a point's error exactly: it counts
  CHECK(p.curve == 0);
  CHECK(p.point == 1);
  CHECK(p.seconds == 2.0);
  p = cheapest_reaching(family, 1e-10);
  CHECK(p.curve == 1);
  CHECK(p.seconds == 9.0);
  CHECK_FALSE(cheapest_reaching(family, 1e-13).found());
  CHECK_FALSE(cheapest_reaching({}, 1.0).found());
}

TEST_CASE("cost to reach: one family below another over a range, at every error in it") {
  SECTION("cheaper everywhere, down to where the other reaches nothing") {
    const std::vector<WorkCurve> ours{{{1.0, 1e-2}, {2.0, 1e-5}, {4.0, 1e-9}}};
    const std::vector<WorkCurve> theirs{{{0.5, 1e-2}, {3.0, 1e-4}, {10.0, 1e-8}}};
    const auto c = compare_cost_to_reach(ours, theirs, 1e-9, 1e-3);
    CHECK(c.ours_cheaper_everywhere);
    CHECK(c.narrowest_ratio == Approx(1.5));  // 3 s against 2 s from 1e-3 down to 1e-5
    CHECK(c.narrowest_error == 1e-3);
  }
  SECTION("between two decades the other family is cheaper: found, though both decades pass") {
    const std::vector<WorkCurve> ours{{{1.0, 1e-3}, {2.0, 1e-4}}};
    const std::vector<WorkCurve> theirs{{{1.5, 5e-4}, {3.0, 1e-5}}};
    CHECK(compare_cost_to_reach(ours, theirs, 1e-3, 1e-3).ours_cheaper_everywhere);
    CHECK(compare_cost_to_reach(ours, theirs, 1e-4, 1e-4).ours_cheaper_everywhere);
    const auto c = compare_cost_to_reach(ours, theirs, 1e-4, 1e-3);
    CHECK_FALSE(c.ours_cheaper_everywhere);
    CHECK(c.narrowest_error == 5e-4);
    CHECK(c.narrowest_ratio == Approx(0.75));
  }
  SECTION("ours reaches nothing at the bottom of the range") {
    const std::vector<WorkCurve> ours{{{1.0, 1e-3}}};
    const std::vector<WorkCurve> theirs{{{5.0, 1e-6}}};
    const auto c = compare_cost_to_reach(ours, theirs, 1e-6, 1e-3);
    CHECK_FALSE(c.ours_cheaper_everywhere);
    CHECK(c.narrowest_ratio == 0.0);
    CHECK(c.narrowest_error == 1e-6);
  }
  SECTION("equal cost is not cheaper") {
    const std::vector<WorkCurve> ours{{{2.0, 1e-4}}};
    const std::vector<WorkCurve> theirs{{{2.0, 1e-4}}};
    CHECK_FALSE(compare_cost_to_reach(ours, theirs, 1e-4, 1e-3).ours_cheaper_everywhere);
  }
  SECTION("a point whose error is not a number reaches nothing") {
    const std::vector<WorkCurve> ours{{{1.0, std::nan("")}, {2.0, 1e-4}}};
    const std::vector<WorkCurve> theirs{{{3.0, 1e-4}}};
    CHECK(cheapest_reaching(ours, 1.0).seconds == 2.0);
    const auto c = compare_cost_to_reach(ours, theirs, 1e-4, 1e-3);
    CHECK(c.ours_cheaper_everywhere);
    CHECK(c.narrowest_ratio == Approx(1.5));
  }
  SECTION("a range that is not one is refused") {
    const std::vector<WorkCurve> one{{{1.0, 1e-3}}};
    CHECK_THROWS_AS(compare_cost_to_reach(one, one, 1e-3, 1e-4), pwl::InputError);
    CHECK_THROWS_AS(compare_cost_to_reach(one, one, 0.0, 1e-4), pwl::InputError);
    CHECK_THROWS_AS(compare_cost_to_reach(one, one, std::nan(""), 1e-4), pwl::InputError);
    CHECK_THROWS_AS(compare_cost_to_reach(one, one, 1e-4, std::numeric_limits<double>::infinity()),
                    pwl::InputError);
  }
}
