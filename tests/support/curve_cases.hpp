#pragma once
// What the bifurcation-curve tests share: where a curve's rows meet a value of the second
// parameter (its ends on an edge of the Q range), and two curves compared there.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/orbits/bifurcation_curves.hpp"

namespace pwl::test {

// P of every row of `r` whose Q is `q` (to 1e-9), in increasing order.
inline std::vector<double> curve_p_at(const orbits::CurvesResult& r, double q) {
  std::vector<double> p;
  for (const orbits::CurvePointRecord& row : r.points) {
    if (std::abs(row.q - q) <= 1e-9) p.push_back(row.p);
  }
  std::sort(p.begin(), p.end());
  return p;
}

// The matrix-free curve meets the edge Q = q once, where the dense curve does, to 1e-8 in P (the
// difference measured as `what`).
inline void check_same_end(const orbits::CurvesResult& dense, const orbits::CurvesResult& free,
                           double q, const std::string& what) {
  const std::vector<double> d = curve_p_at(dense, q), f = curve_p_at(free, q);
  INFO("Q = " << q);
  REQUIRE(d.size() == 1);
  REQUIRE(f.size() == 1);
  measured(what, f[0] - d[0]);
  CHECK(std::abs(f[0] - d[0]) <= 1e-8);
}

}  // namespace pwl::test
