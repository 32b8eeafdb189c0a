// The Newton-Krylov preconditioner J0⁻¹ = (M0 − I)⁻¹, M0 the monodromy of the open structure
// (every gap spring open), against M0 from Eigen's matrix exponential of the 2n x 2n state
// matrix: J0⁻¹ (M0 − I) v must give v back, on each of its three ways to the modes (a diagonal
// mass with a tridiagonal or a wider stiffness, a consistent, non-diagonal mass, and the uniform
// fixed-free chain's closed-form modes by sine transforms), and a damping that is not classical
// must leave it unavailable.
#include <catch2/catch.hpp>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "orbit_cases.hpp"
#include "orbits/open_structure_preconditioner.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/model/gap_structure.hpp"
#include "test_structures.hpp"

using namespace pwl;
using pwl::orbits::detail::OpenStructurePreconditioner;

namespace {

// n masses in a line, grounded at both ends, with springs to the next mass (stiffness 1 + i/n)
// and, when `second` > 0, to the one after it.
Matrix line_stiffness(Index n, double second) {
  Matrix K = Matrix::Zero(n, n);
  for (Index i = 0; i + 1 < n; ++i) test::add_spring(K, i, i + 1, 1.0 + double(i) / double(n));
  for (Index i = 0; second > 0 && i + 2 < n; ++i) test::add_spring(K, i, i + 2, second);
  K(0, 0) += 2.0;
  K(n - 1, n - 1) += 1.5;
  return K;
}

GapStructure open_structure(const Matrix& M, const Matrix& K, const Matrix& C) {
  GapStructure s;
  s.mass = to_sparse(M);
  s.stiffness = to_sparse(K);
  s.damping = to_sparse(C);
  return s;
}

// max over random v of |J0⁻¹ (M0 − I) v − v|_∞ / |v|_∞, M0 = exp(τ H), H the state matrix with
// every spring open.
double round_trip_error(const GapStructure& s, double tau) {
  const Index n = s.dofs();
  const Matrix M0 = Matrix(test::state_matrix(s) * tau).exp();
  const OpenStructurePreconditioner p(s, tau);
  REQUIRE(p.available());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    Vector v(2 * n);
    for (Index i = 0; i < 2 * n; ++i) v(i) = u(rng);
    const Vector r = M0 * v - v;
    worst = std::max(worst, (p.apply(r) - v).lpNorm<Eigen::Infinity>() / v.lpNorm<Eigen::Infinity>());
  }
  return worst;
}

}  // namespace

TEST_CASE("The open structure's preconditioner inverts M0 − I on each of its paths to the modes",
          "[orbits]") {
  const Index n = 16;
  Vector masses(n);
  for (Index i = 0; i < n; ++i) masses(i) = 1.0 + 0.5 * std::sin(double(i));
  const Matrix diagonal_mass = Matrix(masses.asDiagonal());
  const double tau = 2.7;

  SECTION("diagonal mass, tridiagonal stiffness (QR on the tridiagonal K̃ directly)") {
    const Matrix K = line_stiffness(n, 0.0);
    const Matrix C = 0.04 * diagonal_mass + 0.02 * K;  // Rayleigh: classical
    CHECK_FALSE(OpenStructurePreconditioner(open_structure(diagonal_mass, K, C), tau).closed_form());
    CHECK(round_trip_error(open_structure(diagonal_mass, K, C), tau) <= 1e-11);
  }
  SECTION("diagonal mass, stiffness of bandwidth 2 (dense symmetric K̃)") {
    const Matrix K = line_stiffness(n, 0.3);
    const Matrix C = 0.04 * diagonal_mass + 0.02 * K;
    CHECK(round_trip_error(open_structure(diagonal_mass, K, C), tau) <= 1e-11);
  }
  SECTION("consistent (tridiagonal) mass: the generalised problem") {
    Matrix M = diagonal_mass;
    for (Index i = 0; i + 1 < n; ++i) M(i, i + 1) = M(i + 1, i) = 0.1;
    const Matrix K = line_stiffness(n, 0.0);
    const Matrix C = 0.04 * M + 0.02 * K;
    CHECK(round_trip_error(open_structure(M, K, C), tau) <= 1e-11);
  }
  SECTION("uniform fixed-free chain: closed-form modes, sine transforms by FFT or Bluestein") {
    // 2(2n+1) = 30 and 66 factor into small primes (Eigen's FFT directly); 94 = 2 · 47 and
    // 602 = 2 · 7 · 43 take Bluestein's convolution.
    for (const Index size : {Index(7), Index(16), Index(23), Index(150)}) {
      const Matrix M = 1.7 * Matrix::Identity(size, size);
      const Matrix K = 2.3 * Matrix(fixed_free_laplacian(size));
      for (const double a : {0.0, 0.05}) {
        const Matrix C = a * M + 0.2 / 2.3 * K;  // the paper's c = 0.2 between masses when a = 0
        INFO("n = " << size << ", a = " << a);
        CHECK(OpenStructurePreconditioner(open_structure(M, K, C), tau).closed_form());
        CHECK(round_trip_error(open_structure(M, K, C), tau) <= 1e-11);
      }
    }
  }
  SECTION("a dashpot at one end only is not classical damping: unavailable on every path") {
    Matrix C = Matrix::Zero(n, n);
    C(0, 0) = 0.3;
    Matrix consistent = diagonal_mass;
    for (Index i = 0; i + 1 < n; ++i) consistent(i, i + 1) = consistent(i + 1, i) = 0.1;
    CHECK_FALSE(OpenStructurePreconditioner(
                    open_structure(diagonal_mass, line_stiffness(n, 0.0), C), tau)
                    .available());
    CHECK_FALSE(OpenStructurePreconditioner(
                    open_structure(diagonal_mass, line_stiffness(n, 0.3), C), tau)
                    .available());
    CHECK_FALSE(
        OpenStructurePreconditioner(open_structure(consistent, line_stiffness(n, 0.0), C), tau)
            .available());
    // A damping only slightly off proportional (1e-6 of it at one mass) is still refused.
    const Matrix K = line_stiffness(n, 0.0);
    Matrix near = 0.04 * diagonal_mass + 0.02 * K;
    near(3, 3) *= 1.0 + 1e-6;
    CHECK_FALSE(OpenStructurePreconditioner(open_structure(diagonal_mass, K, near), tau).available());
    // Nor is it, on the closed-form path's test, for a uniform chain with such a damping.
    const Matrix uniform = Matrix(fixed_free_laplacian(n));
    CHECK_FALSE(OpenStructurePreconditioner(
                    open_structure(Matrix::Identity(n, n), uniform, C), tau)
                    .available());
  }
}

