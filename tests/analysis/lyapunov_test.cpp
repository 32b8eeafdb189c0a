// Lyapunov exponents against known answers: maps whose exponents are known exactly (logistic map at
// r = 4, linear maps, a periodic orbit) or to several digits (Hénon), and the two estimators
// against each other.
#include "pwl/analysis/lyapunov.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <catch2/catch.hpp>
#include <cmath>

#include "pwl/errors.hpp"
#include "test_series.hpp"

using pwl::Matrix;
using pwl::Vector;
using namespace pwl::analysis;
using Catch::Matchers::Contains;

namespace {

// The logistic and Hénon maps with their Jacobians (test_series.hpp).
TangentMap logistic(double r) { return pwl::test::logistic_map(r); }
TangentMap henon(double a = 1.4, double b = 0.3) { return pwl::test::henon_map(a, b); }

Vector henon_start() {
  Vector x(2);
  x << 0.1, 0.1;
  return x;
}

// exp(A h) for A = [[0, 1], [-w^2, -2 zeta w]], in closed form: with B = A + zeta w I,
// B^2 = w^2 (zeta^2 - 1) I, so exp(A h) = e^{-zeta w h} (c I + s B) with trigonometric
// (underdamped) or hyperbolic (overdamped) c and s.
Matrix oscillator_step(double w, double zeta, double h) {
  Matrix B(2, 2);
  B << zeta * w, 1.0, -w * w, -zeta * w;
  double c = 0.0;
  double s = 0.0;
  if (zeta < 1.0) {
    const double wd = w * std::sqrt(1.0 - zeta * zeta);
    c = std::cos(wd * h);
    s = std::sin(wd * h) / wd;
  } else {
    const double beta = w * std::sqrt(zeta * zeta - 1.0);
    c = std::cosh(beta * h);
    s = std::sinh(beta * h) / beta;
  }
  return std::exp(-zeta * w * h) * (c * Matrix::Identity(2, 2) + s * B);
}

TangentMap linear_map(const Matrix& M) {
  return [M](const Vector& x, Matrix* J) {
    if (J != nullptr) *J = M;
    return Vector(M * x);
  };
}

}  // namespace

TEST_CASE("logistic map at r = 4 has lambda = ln 2", "[lyapunov]") {
  LyapunovOptions options;
  options.iterations = 200000;
  options.transient = 1000;
  const LyapunovResult result = lyapunov_spectrum(logistic(4.0), Vector::Constant(1, 0.1234), options);
  REQUIRE(result.per_iteration.size() == 1);
  CHECK(result.largest() == Approx(std::log(2.0)).margin(1e-2));
  // The convergence estimate is small and honest: the true value lies within a few of it.
  CHECK(result.error[0] > 0.0);
  CHECK(result.error[0] < 1e-2);
  CHECK(std::abs(result.largest() - std::log(2.0)) < 5.0 * result.error[0]);
  CHECK(result.iterations == 200000);
}

TEST_CASE("Henon map spectrum: lambda1 = 0.419, lambda2 = -1.624, sum = ln b", "[lyapunov]") {
  LyapunovOptions options;
  options.iterations = 200000;
  options.transient = 1000;
  const LyapunovResult result = lyapunov_spectrum(henon(), henon_start(), options);
  REQUIRE(result.per_iteration.size() == 2);
  // Each QR step has |R11 R22| = |det J| = 0.3 up to rounding, so the sum is exact.
  CHECK(result.per_iteration.sum() == Approx(std::log(0.3)).margin(1e-12));
  CHECK(result.per_iteration[0] == Approx(0.41922).margin(0.01));
  CHECK(result.per_iteration[1] == Approx(std::log(0.3) - 0.41922).margin(0.01));
  CHECK(result.per_iteration[1] == Approx(-1.62319).margin(0.01));
  CHECK(result.per_iteration[0] > result.per_iteration[1]);
  CHECK(result.error[0] < 0.01);

  SECTION("the top exponent alone is the first of the spectrum") {
    LyapunovOptions top = options;
    top.exponents = 1;
    const LyapunovResult one = lyapunov_spectrum(henon(), henon_start(), top);
    REQUIRE(one.per_iteration.size() == 1);
    CHECK(one.largest() == Approx(result.largest()).margin(1e-12));
  }

  SECTION("a precomputed Jacobian sequence gives the same numbers") {
    // J_n is the derivative at x_n, the state before iteration n.
    std::vector<Matrix> jacobians;
    Vector x = henon_start();
    Matrix J;
    const TangentMap map = henon();
    for (long n = 0; n < options.transient + options.iterations; ++n) {
      Vector next = map(x, &J);
      jacobians.push_back(J);
      x = next;
    }
    const LyapunovResult from_jacobians = lyapunov_spectrum(jacobians, options);
    CHECK(from_jacobians.per_iteration[0] == Approx(result.per_iteration[0]).margin(1e-14));
    CHECK(from_jacobians.per_iteration[1] == Approx(result.per_iteration[1]).margin(1e-14));
    CHECK(from_jacobians.final_state.size() == 0);
  }

  SECTION("rates per unit time divide by the time per iteration") {
    LyapunovOptions timed = options;
    timed.iterations = 20000;
    timed.time_per_iteration = 0.25;
    const LyapunovResult r = lyapunov_spectrum(henon(), henon_start(), timed);
    CHECK(r.per_unit_time[0] == Approx(r.per_iteration[0] / 0.25).epsilon(1e-14));
    CHECK(r.per_unit_time[1] == Approx(r.per_iteration[1] / 0.25).epsilon(1e-14));
    CHECK(r.largest_per_unit_time() == r.per_unit_time[0]);
  }
}

TEST_CASE("a period-2 orbit of the logistic map has lambda = ln|4 + 2r - r^2| / 2", "[lyapunov]") {
  // On the 2-cycle x1, x2: f'(x1) f'(x2) = r^2 (1 - 2 x1)(1 - 2 x2) = 4 + 2r - r^2. After the
  // transient the orbit is the cycle to rounding, and an even number of iterations averages
  // whole cycles, so the estimate is exact.
  const double r = 3.2;
  LyapunovOptions options;
  options.iterations = 10000;
  options.transient = 2000;
  const LyapunovResult result = lyapunov_spectrum(logistic(r), Vector::Constant(1, 0.3), options);
  CHECK(result.largest() == Approx(0.5 * std::log(std::abs(4.0 + 2.0 * r - r * r))).margin(1e-9));
  CHECK(result.largest() < 0.0);
}

TEST_CASE("damped linear oscillator: exponents are the real parts of the eigenvalues", "[lyapunov]") {
  SECTION("underdamped: both exponents -zeta w, error bounded by ln cond(V) / (N h)") {
    // The one-step map J = exp(A h) = V D V^{-1} with |D_ii| = e^{-zeta w h}: J^N q has norm
    // e^{-zeta w N h} times a factor in [1/cond(V), cond(V)] that rotates with the phase. So the
    // QR estimate (1/(N h)) ln |J^N q| is not exact for a complex pair, but its error is at most
    // ln cond(V) / (N h), and lambda1 + lambda2 = ln |det J| / h is exact at every step.
    const double w = 2.0;
    const double zeta = 0.05;
    const double h = 0.1;
    const Matrix J = oscillator_step(w, zeta, h);
    LyapunovOptions options;
    options.iterations = 20000;
    options.transient = 100;
    options.time_per_iteration = h;
    Vector x0(2);
    x0 << 1.0, 0.0;
    const LyapunovResult result = lyapunov_spectrum(linear_map(J), x0, options);

    Eigen::ComplexEigenSolver<Matrix> eigen(J);
    Eigen::MatrixXcd V = eigen.eigenvectors();
    V.colwise().normalize();
    Eigen::JacobiSVD<Eigen::MatrixXcd> svd(V);
    const double condition = svd.singularValues()[0] / svd.singularValues()[1];
    const double bound = std::log(condition) / (options.iterations * h);
    REQUIRE(bound > 0.0);
    REQUIRE(bound < 1e-3);  // the check below is much tighter than the exponent itself (0.1)

    CHECK(std::abs(result.per_unit_time[0] + zeta * w) <= bound * (1.0 + 1e-9));
    CHECK(std::abs(result.per_unit_time[1] + zeta * w) <= bound * (1.0 + 1e-9));
    CHECK(result.per_unit_time.sum() == Approx(-2.0 * zeta * w).margin(1e-12));
    // The reported error covers the actual one, and is of the size of the bound, not far above.
    CHECK(result.error[0] / h >= std::abs(result.per_unit_time[0] + zeta * w));
    CHECK(result.error[0] / h <= 3.0 * bound);
  }

  SECTION("overdamped: two distinct real exponents, exact after the transient") {
    // Eigenvalues -zeta w +- w sqrt(zeta^2 - 1). The transient aligns the frame with the slow
    // eigenvector to (mu2/mu1)^300 = e^{-104}; from then on |J q| = mu1 exactly, so both
    // exponents are exact to rounding.
    const double w = 1.0;
    const double zeta = 2.0;
    const double h = 0.1;
    const double beta = w * std::sqrt(zeta * zeta - 1.0);
    LyapunovOptions options;
    options.iterations = 1000;
    options.transient = 300;
    options.time_per_iteration = h;
    Vector x0(2);
    x0 << 1.0, -0.5;
    const LyapunovResult result = lyapunov_spectrum(linear_map(oscillator_step(w, zeta, h)), x0,
                                                    options);
    CHECK(result.per_unit_time[0] == Approx(-zeta * w + beta).margin(1e-10));
    CHECK(result.per_unit_time[1] == Approx(-zeta * w - beta).margin(1e-10));
    // Exact convergence shows as a vanishing error estimate.
    CHECK(result.error[0] < 1e-12);

    SECTION("two nearby trajectories: exact too, for a linear map") {
      // The separation of two trajectories of a linear map evolves exactly by J, so the
      // renormalised estimate reduces to |J u| with u aligned to the slow eigenvector.
      TwoTrajectoryOptions two;
      two.iterations = 1000;
      two.transient = 300;
      two.time_per_iteration = h;
      const Matrix J = oscillator_step(w, zeta, h);
      const LyapunovResult r = largest_lyapunov_two_trajectories(
          [&J](const Vector& x) { return Vector(J * x); }, x0, two);
      REQUIRE(r.per_unit_time.size() == 1);
      CHECK(r.per_unit_time[0] == Approx(-zeta * w + beta).margin(1e-7));
    }
  }
}

TEST_CASE("two nearby trajectories agree with the QR method on Henon", "[lyapunov]") {
  LyapunovOptions qr_options;
  qr_options.iterations = 100000;
  qr_options.exponents = 1;
  const LyapunovResult qr = lyapunov_spectrum(henon(), henon_start(), qr_options);

  TwoTrajectoryOptions options;
  options.iterations = 100000;
  const TangentMap tangent = henon();
  const LyapunovResult two = largest_lyapunov_two_trajectories(
      [&tangent](const Vector& x) { return tangent(x, nullptr); }, henon_start(), options);
  CHECK(two.largest() == Approx(qr.largest()).margin(0.02));
  CHECK(two.largest() == Approx(0.41922).margin(0.02));
  REQUIRE(two.final_state.size() == 2);
}

TEST_CASE("the random initial frame finds an exponent a coordinate frame would miss", "[lyapunov]") {
  // diag(0.5, 2): e1 spans an invariant contracting subspace. Started from e1 the top exponent
  // would come out as ln 0.5; a generic frame finds ln 2.
  Matrix J(2, 2);
  J << 0.5, 0.0, 0.0, 2.0;
  LyapunovOptions options;
  options.iterations = 100;
  options.transient = 60;
  options.exponents = 1;
  const LyapunovResult result = lyapunov_spectrum(linear_map(J), Vector::Zero(2), options);
  CHECK(result.largest() == Approx(std::log(2.0)).margin(1e-12));
}

TEST_CASE("Lyapunov input errors name the field and the value", "[lyapunov][errors]") {
  LyapunovOptions options;
  options.iterations = 100;
  options.transient = 0;

  SECTION("more exponents than dimensions") {
    options.exponents = 3;
    CHECK_THROWS_MATCHES(lyapunov_spectrum(henon(), henon_start(), options), pwl::InputError,
                         Catch::Matchers::Message(
                             "LyapunovOptions.exponents = 3 exceeds the dimension 2"));
  }
  SECTION("negative exponent count") {
    options.exponents = -1;
    std::string why;
    CHECK_FALSE(options.is_valid(&why));
    CHECK_THAT(why, Contains("exponents") && Contains("-1"));
  }
  SECTION("fewer iterations than blocks") {
    options.iterations = 5;
    CHECK_THROWS_WITH(lyapunov_spectrum(henon(), henon_start(), options),
                      Contains("iterations = 5") && Contains("blocks"));
  }
  SECTION("empty and non-finite initial states") {
    CHECK_THROWS_WITH(lyapunov_spectrum(henon(), Vector(), options), Contains("x0") && Contains("0"));
    Vector x0 = henon_start();
    x0[1] = std::nan("");
    CHECK_THROWS_AS(lyapunov_spectrum(henon(), x0, options), pwl::InputError);
    CHECK_THROWS_WITH(lyapunov_spectrum(henon(), x0, options), Contains("x0[1]") && Contains("nan"));
  }
  SECTION("a Jacobian of the wrong size") {
    const TangentMap bad = [](const Vector& x, Matrix* J) {
      if (J != nullptr) *J = Matrix::Identity(3, 3);
      return x;
    };
    CHECK_THROWS_WITH(lyapunov_spectrum(bad, henon_start(), options),
                      Contains("jacobian") && Contains("3x3") && Contains("2x2"));
  }
  SECTION("a map that forgets the Jacobian") {
    const TangentMap forgetful = [](const Vector& x, Matrix*) { return x; };
    CHECK_THROWS_AS(lyapunov_spectrum(forgetful, henon_start(), options), pwl::InputError);
  }
  SECTION("too short a Jacobian sequence") {
    std::vector<Matrix> jacobians(10, Matrix::Identity(2, 2));
    CHECK_THROWS_WITH(lyapunov_spectrum(jacobians, options), Contains("jacobians") && Contains("10"));
  }
  SECTION("bad options of the two-trajectory estimate") {
    TwoTrajectoryOptions two;
    two.separation = 0.0;
    CHECK_THROWS_WITH(largest_lyapunov_two_trajectories([](const Vector& x) { return x; },
                                                        henon_start(), two),
                      Contains("separation = 0"));
    two = {};
    two.time_per_iteration = -1.0;
    CHECK_THROWS_WITH(largest_lyapunov_two_trajectories([](const Vector& x) { return x; },
                                                        henon_start(), two),
                      Contains("time_per_iteration = -1"));
  }
  SECTION("a diverging map is a DivergenceError") {
    const TangentMap doubling = [](const Vector& x, Matrix* J) {
      if (J != nullptr) *J = Matrix::Constant(1, 1, 2.0);
      return Vector(2.0 * x.array() + 1.0);
    };
    CHECK_THROWS_AS(lyapunov_spectrum(doubling, Vector::Constant(1, 1.0), options),
                    pwl::DivergenceError);
  }
  SECTION("coinciding trajectories are a DivergenceError") {
    TwoTrajectoryOptions two;
    two.iterations = 100;
    const StateMap constant = [](const Vector& x) { return Vector(Vector::Zero(x.size())); };
    CHECK_THROWS_AS(largest_lyapunov_two_trajectories(constant, henon_start(), two),
                    pwl::DivergenceError);
  }
}
