// A period-doubling curve of a long chain, matrix-free: the paper's kind of chain of 100 masses
// (α = 2, ζ = 0.2, Δ̃ = 0, loads ±1 on alternate masses) has, past the Neimark–Sacker points where
// its period-1 orbit lost stability, a period doubling at θ = 0.51962 with up to 20 multipliers
// outside the circle (matrix_free_long_chain_doubling_test.cpp). Its curve in (θ, α) over α ∈
// [1.95, 2.05], on the banded switching PIM, followed matrix-free (Newton–Krylov on the bordered
// test function of M + I, Arnoldi for the multipliers: its basis as large as the operator, so that
// a multiplier on the circle among many outside is found in one cycle) and dense (the whole
// 200 x 200 monodromy and its derivatives at every point):
//  - both cross the α range, their ends on its edges within 1e-8 in θ of each other;
//  - at points of the matrix-free curve the dense monodromy has a multiplier at −1 (1e-8);
//  - no monodromy is formed by the matrix-free curve.
// (Release build only.)
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "continuation_cases.hpp"
#include "curve_cases.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;
using pwl::test::paper_chain;

namespace {

constexpr int kMasses = 100;

}  // namespace

TEST_CASE("a long chain's period-doubling curve, matrix-free, is the dense one", "[orbits]") {
  const NondimensionalChain chain = paper_chain(kMasses, 0.5192);
  const MethodSettings method{Method::pim_switching_banded};
  StroboscopicMap settle(analysis::PointCase(chain), method, 200);
  const Vector guess = settle.advance(Vector::Zero(2 * kMasses), 50);
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 0.5192;
  o.end = 0.5200;
  o.method = method;
  o.steps_per_period = 200;
  o.max_points = 40;
  o.shooting.arnoldi.krylov_dimension = 120;
  o.shooting.arnoldi.davidson_dimension = 120;
  const ContinuationResult branch = pwl::test::follow(chain, guess, o, ShootingSolver::krylov);
  const Bifurcation* doubling = pwl::test::first_doubling(branch);
  REQUIRE(doubling != nullptr);

  CurvesResult r[2];
  for (const bool matrix_free : {false, true}) {
    CurvesOptions c;
    c.first = analysis::SweepParameter::theta;
    c.second = analysis::SweepParameter::alpha;
    c.p_from = 0.5;
    c.p_to = 0.54;
    c.q_from = 1.95;
    c.q_to = 2.05;
    c.types = {CurveType::period_doubling};
    c.method = method;
    c.steps_per_period = 200;
    c.shooting.solver = matrix_free ? ShootingSolver::krylov : ShootingSolver::dense;
    r[matrix_free] = follow_bifurcation_curves(analysis::PointModel(chain), {*doubling}, c);
    REQUIRE(r[matrix_free].curves.size() == 1);
  }
  CHECK(r[1].monodromies == 0);
  CHECK(r[1].krylov_products > 0);
  // Every corrected point's leading multipliers by Davidson preconditioned by the open structure
  // (classical damping), none by Arnoldi; the dense curve forms the monodromy instead. (The
  // curve's first point, a row of each direction, is corrected twice: on the curve's equations
  // with q held, then again after the system's refresh.)
  CHECK(r[1].davidson_points >= static_cast<int>(r[1].points.size()));
  CHECK(r[1].arnoldi_points == 0);
  CHECK(r[0].davidson_points + r[0].arnoldi_points == 0);
  for (const double edge : {1.95, 2.05}) {
    pwl::test::check_same_end(
        r[0], r[1], edge, "100 masses: matrix-free - dense period-doubling curve theta at an edge");
  }
  // The dense monodromy at three points of the matrix-free curve.
  std::vector<const CurvePointRecord*> rows;
  for (const CurvePointRecord& row : r[1].points) rows.push_back(&row);
  REQUIRE(rows.size() >= 12);
  for (std::size_t i = 3; i < rows.size(); i += rows.size() / 3) {
    const CurvePointRecord& p = *rows[i];
    NondimensionalChain at = paper_chain(kMasses, p.p);
    at.alpha = {p.q};
    StroboscopicMap map(analysis::PointCase(at), method, 200);
    Matrix M;
    map.advance_with_jacobian(p.state, 1, M);
    double flip = 1e300;
    for (const auto& m : floquet_multipliers(M).values) flip = std::min(flip, std::abs(m + 1.0));
    INFO("theta = " << p.p << ", alpha = " << p.q);
    measured("100 masses: matrix-free period-doubling curve, |mu + 1| of the dense monodromy",
             flip);
    CHECK(flip <= 1e-8);
  }
}
