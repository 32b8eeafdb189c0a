// The 2^N algorithm and its inverse-free load integrals against Eigen's matrix exponential
// (scaling and squaring with Padé approximants: an independent algorithm) of Van Loan's
// block-triangular matrices, which contain the same integrals as blocks.
#include <catch2/catch.hpp>
#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>
#include <random>

#include "pwl/errors.hpp"
#include "pwl/integrators/switching_pim.hpp"
#include "pwl/numerics/precise_exponential.hpp"

using namespace pwl;

namespace {

Matrix random_state_matrix(int n, unsigned seed, double damping) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Matrix A(n, n);
  for (Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  const Matrix K = A * A.transpose() + 0.1 * Matrix::Identity(n, n);
  Matrix H = Matrix::Zero(2 * n, 2 * n);
  H.topRightCorner(n, n).setIdentity();
  H.bottomLeftCorner(n, n) = -K;
  H.bottomRightCorner(n, n) = -damping * K;
  return H;
}

double relative_error(const Matrix& a, const Matrix& b) {
  return (a - b).norm() / std::max(1e-300, b.norm());
}

// Van Loan's block exponential exp([[H, G, 0], [0, 0, I], [0, 0, 0]] η), whose top blocks are
// ∫ e^{Hu} du G and ∫ e^{H(η-s)} s ds G; the full matrix for T = its top-left block.
Matrix van_loan_blocks(const Matrix& H, const Matrix& G, double eta) {
  const Index s = H.rows(), m = G.cols();
  Matrix A = Matrix::Zero(s + 2 * m, s + 2 * m);
  A.topLeftCorner(s, s) = H;
  A.block(0, s, s, m) = G;
  A.block(s, s + m, m, m).setIdentity();
  return (A * eta).exp();
}

// exp([[H, b, 0], [0, 0, -ω], [0, ω, 0]] η): the column fed by w(0) = (1, 0) is
// ∫ e^{H(η-s)} b cos ωs ds = Re K b, the one fed by (0, 1) is -∫ e^{H(η-s)} b sin ωs ds = -Im K b.
Matrix van_loan_harmonic(const Matrix& H, const Vector& b, double omega, double eta) {
  const Index s = H.rows();
  Matrix A = Matrix::Zero(s + 2, s + 2);
  A.topLeftCorner(s, s) = H;
  A.block(0, s, s, 1) = b;
  A(s, s + 1) = -omega;
  A(s + 1, s) = omega;
  return (A * eta).exp();
}

}  // namespace

TEST_CASE("2^N exponential matches Eigen's Pade exponential", "[precise_exponential]") {
  for (int n : {1, 3, 6}) {
    for (double eta : {0.01, 0.3, 2.0}) {
      const Matrix H = random_state_matrix(n, 7u + static_cast<unsigned>(n), 0.05);
      const Matrix T = precise_exponential(H, eta);
      const Matrix expected = (H * eta).exp();
      INFO("n = " << n << ", eta = " << eta);
      CHECK(relative_error(T, expected) < 1e-12);
    }
  }
}

TEST_CASE("Gamma0 and Gamma1 match Van Loan's block exponential", "[precise_exponential]") {
  // exp([[H, G, 0], [0, 0, I], [0, 0, 0]] η) has top blocks ∫ e^{Hu} du G and ∫ e^{H(η-s)} s ds G;
  // Γ1 = ∫ e^{Hu} u du = η Γ0 - ∫ e^{H(η-s)} s ds.
  const int n = 4, m = 3;
  const Matrix H = random_state_matrix(n, 11u, 0.1);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  Matrix G(2 * n, m);
  for (Index i = 0; i < G.size(); ++i) G.data()[i] = normal(rng);
  for (double eta : {0.05, 0.7}) {
    const Matrix E = van_loan_blocks(H, G, eta);
    const Matrix gamma0 = E.block(0, 2 * n, 2 * n, m);
    const Matrix moment = E.block(0, 2 * n + m, 2 * n, m);
    const PreciseExponential p = precise_exponential(H, eta, G, Matrix(2 * n, 0), Vector(0));
    INFO("eta = " << eta);
    CHECK(relative_error(p.gamma0, gamma0) < 1e-12);
    CHECK(relative_error(p.gamma1, eta * gamma0 - moment) < 1e-11);
  }
}

TEST_CASE("Harmonic load integrals match Van Loan's block exponential", "[precise_exponential]") {
  // Van Loan's harmonic blocks (van_loan_harmonic).
  const int n = 3;
  for (double damping : {0.0, 0.2}) {
    const Matrix H = random_state_matrix(n, 3u, damping);
    Vector b = Vector::Zero(2 * n);
    b.tail(n) << 1.0, -2.0, 0.5;
    for (double omega : {0.0, 0.8, 3.0}) {
      const double eta = 0.4;
      const Matrix E = van_loan_harmonic(H, b, omega, eta);
      Vector w(1);
      w << omega;
      const PreciseExponential p = precise_exponential(H, eta, Matrix(2 * n, 0), b, w);
      INFO("omega = " << omega << ", damping = " << damping);
      CHECK(relative_error(p.harmonic_real, E.block(0, 2 * n, 2 * n, 1)) < 1e-12);
      if (omega > 0.0) {
        CHECK(relative_error(p.harmonic_imag, -E.block(0, 2 * n + 1, 2 * n, 1)) < 1e-12);
      } else {
        CHECK(p.harmonic_imag.norm() < 1e-14);
      }
    }
  }
}

TEST_CASE("Singular H: the integrals need no inverse", "[precise_exponential]") {
  // A free mass: H = [[0, 1], [0, 0]]. Γ0 G with G = [0; 1] is [η²/2; η].
  Matrix H(2, 2);
  H << 0, 1, 0, 0;
  Matrix G(2, 1);
  G << 0, 1;
  const double eta = 0.37;
  const PreciseExponential p = precise_exponential(H, eta, G, Matrix(2, 0), Vector(0));
  CHECK(p.transition(0, 1) == Approx(eta).epsilon(1e-15));
  CHECK(p.gamma0(0, 0) == Approx(eta * eta / 2).epsilon(1e-14));
  CHECK(p.gamma0(1, 0) == Approx(eta).epsilon(1e-14));
  // Γ1 G = ∫ [u²/2... ]: ∫_0^η [u; 1] u du = [η³/3; η²/2].
  CHECK(p.gamma1(0, 0) == Approx(eta * eta * eta / 3).epsilon(1e-14));
  CHECK(p.gamma1(1, 0) == Approx(eta * eta / 2).epsilon(1e-14));
}

TEST_CASE("Trimmed doublings are exact to rounding, as the paper's N = 20", "[precise_exponential]") {
  const PreciseExponentialOptions paper;  // the default: always N = 20
  PreciseExponentialOptions trimmed;
  trimmed.trim_doublings = true;
  // How many: ‖Hη‖₁ = 1 at order 4 needs θ = 2^-N <= (5! 2^-53)^(1/4) = 3.4e-4, so N = 12; at
  // order 8 (9! 2^-53)^(1/8) = 0.050, so N = 5; a tiny H none; a huge one stops at the cap.
  Matrix unit = Matrix::Zero(2, 2);
  unit(0, 1) = 1.0;
  CHECK(doublings_used(unit, 1.0, 0.0, trimmed) == 12);
  CHECK(doublings_used(unit, 1.0, 0.0, paper) == 20);
  CHECK(doublings_used(unit, 2.0, 0.0, trimmed) == 13);
  CHECK(doublings_used(unit, 0.5, 1.5, trimmed) == 12);  // the load frequency counts
  CHECK(doublings_used(unit, 1e-5, 0.0, trimmed) == 0);
  CHECK(doublings_used(unit, 1e6, 0.0, trimmed) == 20);
  PreciseExponentialOptions order8 = trimmed;
  order8.taylor_order = 8;
  CHECK(doublings_used(unit, 1.0, 0.0, order8) == 5);
  // Long series stop at θ = 1/2 ((17! 2^-53)^(1/16) = 0.82 would allow 0.7).
  PreciseExponentialOptions order16 = trimmed;
  order16.taylor_order = 16;
  CHECK(doublings_used(unit, 0.7, 0.0, order16) == 1);
  // The larger of the column and row sums (row sum 4, column sums 1, and transposed): with one
  // of them alone, θ = 1/4 would take N = 10.
  Matrix lopsided = Matrix::Zero(5, 5);
  lopsided.row(0).tail(4).setOnes();
  CHECK(doublings_used(lopsided, 0.25, 0.0, trimmed) == 12);
  CHECK(doublings_used(lopsided.transpose(), 0.25, 0.0, trimmed) == 12);

  // The undamped unit oscillator in closed form: exp(Hη) = [[cos η, sin η], [-sin η, cos η]].
  Matrix oscillator(2, 2);
  oscillator << 0.0, 1.0, -1.0, 0.0;
  for (const PreciseExponentialOptions& o : {trimmed, order8}) {
    for (double eta : {1e-4, 0.02, 0.2, 1.0, 3.0}) {
      const Matrix T = precise_exponential(oscillator, eta, o);
      INFO("order " << o.taylor_order << ", eta = " << eta
                    << ", N = " << doublings_used(oscillator, eta, 0.0, o));
      CHECK(std::abs(T(0, 0) - std::cos(eta)) < 4e-16);
      CHECK(std::abs(T(0, 1) - std::sin(eta)) < 4e-16);
      CHECK(std::abs(T(1, 0) + std::sin(eta)) < 4e-16);
      CHECK(std::abs(T(1, 1) - std::cos(eta)) < 4e-16);
    }
  }

  // Every output over ‖Hη‖ from 1e-3 to 100, at orders 4 and 8: as close to Eigen's Padé
  // exponential (and to Van Loan's blocks) as the paper's N = 20 is, the two within rounding of
  // each other, and not the same bits (the trimmed run did run fewer doublings).
  const int n = 4, m = 2;
  std::mt19937 rng(17);
  std::normal_distribution<double> normal;
  Matrix G(2 * n, m);
  for (Index i = 0; i < G.size(); ++i) G.data()[i] = normal(rng);
  Vector b = Vector::Zero(2 * n);
  b.tail(n) << 1.0, -2.0, 0.5, 0.7;
  const Matrix H = random_state_matrix(n, 23u, 0.05);
  const double norm = std::max(H.cwiseAbs().colwise().sum().maxCoeff(),
                               H.cwiseAbs().rowwise().sum().maxCoeff());
  for (const PreciseExponentialOptions& o : {trimmed, order8}) {
    for (double size : {1e-3, 0.1, 1.0, 10.0, 100.0}) {
      const double eta = size / norm;
      const double omega = 3.0 / eta;  // |ω|η = 3, beside ‖Hη‖
      Vector omegas(1);
      omegas << omega;
      const int N = doublings_used(H, eta, omega, o);
      INFO("order " << o.taylor_order << ", ||H eta|| = " << size << ", N = " << N);
      CHECK(N < 20);
      const Matrix E = van_loan_blocks(H, G, eta);
      const Matrix gamma0 = E.block(0, 2 * n, 2 * n, m);
      const Matrix gamma1 = eta * gamma0 - E.block(0, 2 * n + m, 2 * n, m);
      const Matrix harmonic = van_loan_harmonic(H, b, omega, eta);
      const PreciseExponential a = precise_exponential(H, eta, G, b, omegas, o);
      const PreciseExponential p = precise_exponential(H, eta, G, b, omegas, paper);
      const auto as_close = [](const Matrix& got, const Matrix& paper_got, const Matrix& truth) {
        return relative_error(got, truth) <= std::max(2.0 * relative_error(paper_got, truth), 2e-14);
      };
      CHECK(as_close(a.transition, p.transition, E.topLeftCorner(2 * n, 2 * n)));
      CHECK(as_close(a.gamma0, p.gamma0, gamma0));
      CHECK(as_close(a.gamma1, p.gamma1, gamma1));
      CHECK(as_close(a.harmonic_real, p.harmonic_real, harmonic.block(0, 2 * n, 2 * n, 1)));
      CHECK(as_close(a.harmonic_imag, p.harmonic_imag, -harmonic.block(0, 2 * n + 1, 2 * n, 1)));
      CHECK(relative_error(a.transition, p.transition) < 1e-13);
      CHECK(relative_error(a.gamma0, p.gamma0) < 1e-13);
      CHECK(relative_error(a.gamma1, p.gamma1) < 1e-13);
      CHECK(relative_error(a.harmonic_real, p.harmonic_real) < 1e-13);
      CHECK(relative_error(a.harmonic_imag, p.harmonic_imag) < 1e-13);
      CHECK(a.transition != p.transition);
      // The moments of polynomial forces run the same doublings (no load frequency).
      const PolynomialForceIntegrals pa = polynomial_force_integrals(H, eta, G, 3, o);
      const PolynomialForceIntegrals pb = polynomial_force_integrals(H, eta, G, 3, paper);
      CHECK(doublings_used(H, eta, 0.0, o) <= N);
      CHECK(relative_error(pa.transition, pb.transition) < 1e-13);
      CHECK(as_close(pa.moments[0], pb.moments[0], gamma0));
      for (std::size_t r = 0; r < pa.moments.size(); ++r) {
        CHECK(relative_error(pa.moments[r], pb.moments[r]) < 1e-13);
      }
    }
  }
}

TEST_CASE("Bad input to the exponential is named", "[precise_exponential]") {
  const Matrix H = Matrix::Identity(2, 2);
  CHECK_THROWS_WITH(precise_exponential(H, 0.0), Catch::Contains("step = 0"));
  CHECK_THROWS_WITH(precise_exponential(H, -1.0), Catch::Contains("step = -1"));
  CHECK_THROWS_AS(precise_exponential(Matrix(2, 3), 1.0), InputError);
  Matrix bad = H;
  bad(0, 1) = std::nan("");
  CHECK_THROWS_WITH(precise_exponential(bad, 1.0), Catch::Contains("H has a non-finite"));
  PreciseExponentialOptions options;
  options.doublings = -1;
  CHECK_THROWS_WITH(precise_exponential(H, 1.0, options), Catch::Contains("doublings = -1"));
}
