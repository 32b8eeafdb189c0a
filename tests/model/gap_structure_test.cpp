// The structure model: validation names the field and value, derived quantities (W, g, P, load
// groups, the common period) against hand-computed values, and the paper's chain builders.
#include <catch2/catch.hpp>

#include <cmath>

#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/model/gap_structure.hpp"
#include "test_structures.hpp"

using namespace pwl;

namespace {

GapStructure two_masses() {
  GapStructure s;
  Matrix K(2, 2);
  K << 3, -1, -1, 1;
  s.mass = to_sparse(Matrix::Identity(2, 2));
  s.damping = to_sparse(0.1 * K);
  s.stiffness = to_sparse(K);
  s.springs.push_back({0, -1, 1.0, 5.0, 0.1});   // mass 0 against a stop on its right
  s.springs.push_back({1, 0, -1.0, 2.0, -0.05}); // preloaded clearance: closes as x1 - x0 shrinks
  return s;
}

SparseMatrix symmetric_2x2(double diagonal0, double off_diagonal, double diagonal1) {
  Matrix A(2, 2);
  A << diagonal0, off_diagonal, off_diagonal, diagonal1;
  return to_sparse(A);
}

std::string why_invalid(const GapStructure& s) {
  std::string why;
  CHECK_FALSE(s.is_valid(&why));
  return why;
}

}  // namespace

TEST_CASE("Gap functions, spring forces and W", "[structure]") {
  const GapStructure s = two_masses();
  REQUIRE(s.is_valid(nullptr));
  Vector x(2);
  x << 0.3, 0.2;
  const Vector g = s.gap_functions(x);
  CHECK(g[0] == Approx(0.3 - 0.1));
  CHECK(g[1] == Approx(-(0.2 - 0.3) + 0.05));
  const Vector p = s.spring_forces(x);
  CHECK(p[0] == Approx(5.0 * 0.2));
  CHECK(p[1] == Approx(2.0 * 0.15));
  x << -0.3, 0.2;  // spring 0 slack, clearance open
  CHECK(s.spring_forces(x)[0] == 0.0);
  CHECK(s.spring_forces(x)[1] == 0.0);
  const Matrix W = s.spring_directions();
  Matrix expected(2, 2);
  expected << 1, 1, 0, -1;
  CHECK((W - expected).norm() == 0.0);
}

TEST_CASE("Loads group by frequency and keep their phase", "[structure]") {
  GapStructure s = two_masses();
  s.loads.push_back({0, 2.0, 3.0, 0.0});
  s.loads.push_back({1, 1.0, 3.0, M_PI / 2});  // cos 3t
  s.loads.push_back({1, -1.0, 5.0, 0.3});
  const auto groups = s.load_groups();
  REQUIRE(groups.size() == 2);
  for (double t : {0.0, 0.4, 2.7}) {
    Vector f = Vector::Zero(2);
    for (const LoadGroup& g : groups) {
      f += g.sin_part * std::sin(g.omega * t) + g.cos_part * std::cos(g.omega * t);
    }
    CHECK((f - s.load(t)).norm() < 1e-14);
    CHECK(s.load(t)[1] == Approx(std::cos(3 * t) - std::sin(5 * t + 0.3)));
  }
}

TEST_CASE("The common period of commensurate loads", "[structure]") {
  GapStructure s = two_masses();
  s.loads.push_back({0, 1.0, 3.0, 0.0});
  CHECK(s.common_period() == Approx(2 * M_PI / 3));
  s.loads.push_back({1, 1.0, 5.0, 0.0});
  CHECK(s.common_period() == Approx(2 * M_PI));  // gcd(3, 5) = 1
  s.loads.push_back({1, 1.0, 1.5, 0.0});
  CHECK(s.common_period() == Approx(4 * M_PI));  // fundamental 0.5
  s.loads.push_back({1, 1.0, std::sqrt(2.0), 0.0});
  CHECK_THROWS_WITH(s.common_period(), Catch::Contains("incommensurate"));
  GapStructure quiet = two_masses();
  CHECK_THROWS_WITH(quiet.common_period(), Catch::Contains("no time-varying load"));
}

TEST_CASE("Validation names the field and the value", "[structure]") {
  GapStructure s = two_masses();
  s.mass.coeffRef(1, 1) = -2.0;
  CHECK_THAT(why_invalid(s), Catch::Contains("mass[1,1] = -2"));
  s = two_masses();
  s.mass.coeffRef(0, 0) = std::nan("");
  CHECK_THAT(why_invalid(s), Catch::Contains("mass[0,0] = nan"));
  s = two_masses();
  s.damping.coeffRef(0, 0) = -0.5;
  CHECK_THAT(why_invalid(s), Catch::Contains("damping[0,0] = -0.5"));
  s = two_masses();
  s.stiffness.coeffRef(0, 1) = 7.0;
  CHECK_THAT(why_invalid(s), Catch::Contains("stiffness is not symmetric"));
  s = two_masses();
  s.stiffness = to_sparse(Matrix::Identity(3, 3));
  CHECK_THAT(why_invalid(s), Catch::Contains("stiffness is 3x3, expected 2x2"));
  s = two_masses();
  s.stiffness = symmetric_2x2(1, 2, 1);
  CHECK_THAT(why_invalid(s), Catch::Contains("not positive semidefinite"));
  s = two_masses();
  s.springs[1].stiffness = -1.0;
  CHECK_THAT(why_invalid(s), Catch::Contains("springs[1].stiffness = -1"));
  s = two_masses();
  s.springs[0].dof = 4;
  CHECK_THAT(why_invalid(s), Catch::Contains("springs[0].dof = 4"));
  s = two_masses();
  s.springs[0].direction = 0.5;
  CHECK_THAT(why_invalid(s), Catch::Contains("springs[0].direction = 0.5"));
  s = two_masses();
  s.loads.push_back({0, 1.0, -3.0, 0.0});
  CHECK_THAT(why_invalid(s), Catch::Contains("loads[0].omega = -3"));
  s = two_masses();
  s.loads.push_back({0, std::numeric_limits<double>::infinity(), 3.0, 0.0});
  CHECK_THAT(why_invalid(s), Catch::Contains("loads[0].amplitude = inf"));
  CHECK_THROWS_AS(s.validate(), InputError);
  // A free-free stiffness is semidefinite and valid.
  s = two_masses();
  s.stiffness = symmetric_2x2(1, -1, 1);
  CHECK(s.is_valid(nullptr));
  // An indefinite stiffness whose LDL^T stops at its first (zero) pivot is not semidefinite.
  s = two_masses();
  s.stiffness = symmetric_2x2(0, 1, 0);
  CHECK_THAT(why_invalid(s), Catch::Contains("stiffness is not positive semidefinite"));
  // Zero damping with its zeros stored is semidefinite.
  s = two_masses();
  s.damping = to_sparse(Matrix::Zero(2, 2));
  for (Index i = 0; i < 2; ++i) {
    for (Index j = 0; j < 2; ++j) s.damping.coeffRef(i, j) = 0.0;
  }
  REQUIRE(s.damping.nonZeros() == 4);
  CHECK(s.is_valid(nullptr));
  s.stiffness = to_sparse(Matrix::Zero(2, 2));
  s.damping = symmetric_2x2(0, 1, 0);
  CHECK_THAT(why_invalid(s), Catch::Contains("damping is not positive semidefinite"));
}

TEST_CASE("Definiteness of wide and narrow bands", "[structure]") {
  // A ring of 100 masses (a coupling from the last to the first: bandwidth 99, factorised in a
  // fill-reducing order) and the same chain open (bandwidth 1, natural order): free-free and
  // grounded, valid; with one coupling entry too large for its diagonal, not.
  for (bool ring : {false, true}) {
    const int n = 100;
    Matrix K = Matrix::Zero(n, n);
    for (int i = 0; i + 1 < n; ++i) pwl::test::add_spring(K, i, i + 1, 1.0);
    if (ring) pwl::test::add_spring(K, n - 1, 0, 1.0);
    GapStructure s;
    s.mass = to_sparse(Matrix::Identity(n, n));
    s.damping = to_sparse(Matrix::Zero(n, n));
    s.stiffness = to_sparse(K);
    INFO((ring ? "ring" : "open chain"));
    CHECK(s.is_valid(nullptr));  // free-free: semidefinite
    K(0, 0) += 2.0;               // grounded at mass 0
    s.stiffness = to_sparse(K);
    CHECK(s.is_valid(nullptr));
    // A coupling entry too large for its diagonal: [[2, -5], [-5, 2]] has an eigenvalue -3.
    K(n / 2, n / 2 + 1) = K(n / 2 + 1, n / 2) = -5.0;
    s.stiffness = to_sparse(K);
    const std::string why = why_invalid(s);
    CHECK_THAT(why, Catch::Contains("stiffness is not positive semidefinite"));
  }
}

TEST_CASE("The paper's chains", "[structure]") {
  const GapStructure large = make_chain(paper_large_chain(10));
  CHECK(large.dofs() == 10);
  CHECK(large.spring_count() == 10);
  const Matrix K = Matrix(large.stiffness);
  CHECK(K(0, 0) == 2.0);
  CHECK(K(9, 9) == 1.0);  // the last mass is free on its right
  CHECK(K(3, 4) == -1.0);
  CHECK(Matrix(large.damping)(5, 5) == Approx(0.4));
  CHECK(large.load(0.3)[0] == Approx(std::sin(0.9)));    // mass 1 (odd)
  CHECK(large.load(0.3)[1] == Approx(-2 * std::sin(1.5))); // mass 2 (even)
  CHECK(large.common_period() == Approx(2 * M_PI));

  const NondimensionalChain c = paper_five_dof_case("4b");
  const GapStructure five = make_chain(c);
  CHECK(five.springs[2].stiffness == 8.0);
  CHECK(five.springs[2].gap == 0.1);
  CHECK(five.load(0.5)[1] == Approx(-std::sin(0.5)));
  CHECK(c.period() == Approx(2 * M_PI));
  CHECK(Matrix(five.damping)(0, 1) == Approx(-0.2));
  CHECK_THROWS_WITH(paper_five_dof_case("7"), Catch::Contains("figure = \"7\""));

  NondimensionalChain bad = c;
  bad.gap = {0.1, 0.2};
  CHECK_THROWS_WITH(make_chain(bad), Catch::Contains("gap has 2 values"));
  bad = c;
  bad.theta = 0.0;
  CHECK_THROWS_WITH(make_chain(bad), Catch::Contains("theta = 0"));
  ChainParameters p = paper_large_chain(4);
  p.mass = {1.0, 1.0, -1.0, 1.0};
  CHECK_THROWS_WITH(make_chain(p), Catch::Contains("mass[2] = -1"));
}
