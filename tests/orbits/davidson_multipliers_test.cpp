// The leading multipliers by preconditioned Davidson (preconditioned_floquet_multipliers) against
// spectra known by construction, on the same crowds as Arnoldi's tests (krylov_shooting_test.cpp)
// and with Arnoldi run on the same operator: A = S D S⁻¹ with D the rotation-scaling blocks of a
// long chain's long waves crowded against the unit circle, and a preconditioner built as the
// chain's is, from a nearby linear operator A0 = S D0 S⁻¹ whose waves sit elsewhere (the open
// structure's M0: its angles are not the orbit's). Checked: the values to 1e-9, the Ritz vectors
// as eigenvectors, the band round the circle reported whole or said not to be, every multiplier
// outside the circle found, the whole space at once, a warm start (Davidson's and Arnoldi's, from
// the real Schur vectors of the Ritz vectors given, themselves checked against a real Schur
// form), and the products against Arnoldi's on the same data.
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <catch2/catch.hpp>
#include <complex>
#include <limits>
#include <random>
#include <vector>

#include "known_spectra.hpp"
#include "orbit_cases.hpp"
#include "orbits/multiplier_sorting.hpp"
#include "orbits/schur_vectors.hpp"
#include "pwl/orbits/floquet_multipliers.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;
using pwl::test::put_pair;
using pwl::test::set_distance;
using Complex = std::complex<double>;

namespace {

// An operator A = S D S⁻¹ and its preconditioner (S D0 S⁻¹ − σI)⁻¹, S a random well-conditioned
// basis (known_spectra.hpp).
struct Case {
  Matrix A;
  Matrix S, S_inverse;
  Matrix D0;
  std::vector<Complex> spectrum;  // of D (and A)

  Case(const Matrix& D, Matrix open, std::vector<Complex> values, std::mt19937& rng)
      : D0(std::move(open)), spectrum(std::move(values)) {
    S = pwl::test::random_basis(D.rows(), rng);
    S_inverse = S.inverse();
    A = S * D * S_inverse;
  }

  Index size() const { return A.rows(); }

  ShiftedInverse inverse() const {
    // D0 is block diagonal (2 x 2 blocks at even indices): solved block by block.
    return [this](const Eigen::VectorXcd& r, Complex sigma) -> Eigen::VectorXcd {
      Eigen::VectorXcd q = S_inverse.cast<Complex>() * r;
      for (Index i = 0; i + 1 < q.size(); i += 2) {
        Eigen::Matrix2cd K = D0.block<2, 2>(i, i).cast<Complex>();
        K.diagonal().array() -= sigma;
        q.segment<2>(i) = K.inverse() * q.segment<2>(i).eval();
      }
      return S.cast<Complex>() * q;
    };
  }
};

// A long chain's crowd: pairs (1 − c k²) e^{±a k i} for k = 1 .. pairs (the first `outside`
// of them scaled by `lift`), the rest of the space in a disc of radius `rest`; D0 the open
// structure's: the same moduli at the angles a (k − ½) (a fixed-free chain's against a chain
// whose contacts hold its end, as on the paper's chain).
Case crowd(Index n, int pairs, double c, double a, double rest, std::mt19937& rng,
           int outside = 0, double lift = 1.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix D = Matrix::Zero(n, n), D0 = Matrix::Zero(n, n);
  std::vector<Complex> all;
  for (int k = 1; k <= pairs; ++k) {
    const double r = (1.0 - c * k * k) * (k <= outside ? lift : 1.0), phi = a * k;
    put_pair(D, 2 * (k - 1), r, phi);
    put_pair(D0, 2 * (k - 1), 1.0 - c * k * k, a * (k - 0.5));
    all.push_back(std::polar(r, phi));
    all.push_back(std::polar(r, -phi));
  }
  for (Index i = 2 * pairs; i + 1 < n; i += 2) {
    const double r = rest * std::abs(u(rng)), phi = 3.2 * u(rng);
    put_pair(D, i, r, phi);
    put_pair(D0, i, r, phi + 0.05);
    all.push_back(std::polar(r, phi));
    all.push_back(std::polar(r, -phi));
  }
  return Case(D, D0, all, rng);
}

// The values of `all` with modulus above `edge`, and the `count` of largest modulus.
std::vector<Complex> in_band(const std::vector<Complex>& all, double edge) {
  std::vector<Complex> out;
  for (const Complex& mu : all) {
    if (std::abs(mu) > edge) out.push_back(mu);
  }
  return out;
}
std::vector<Complex> leading(std::vector<Complex> all, std::size_t count) {
  std::stable_sort(all.begin(), all.end(),
                   [](Complex x, Complex y) { return std::abs(x) > std::abs(y); });
  all.resize(count);
  return all;
}

// The farthest value of `wanted` from its nearest in `found`.
double farthest(const std::vector<Complex>& wanted, const std::vector<Complex>& found) {
  double worst = 0.0;
  for (const Complex& w : wanted) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Complex& f : found) nearest = std::min(nearest, std::abs(f - w));
    worst = std::max(worst, nearest);
  }
  return worst;
}

}  // namespace

TEST_CASE("preconditioned Davidson resolves a crowd of long waves in fewer products than Arnoldi",
          "[orbits]") {
  // The crowd of the Arnoldi test: (1 − 4e-6 k²) e^{±0.0131 k i}, k = 1 .. 200, in 1000
  // dimensions, the rest in a disc of radius 0.9.
  std::mt19937 rng(11);
  const Case c = crowd(1000, 200, 4e-6, 0.0131, 0.9, rng);
  long products = 0;
  const auto apply = [&](Matrix& v) {
    products += v.cols();
    v = c.A * v;
  };
  ArnoldiOptions options;
  options.count = 6;
  options.block = 2;
  Eigen::MatrixXcd vectors;
  const FloquetMultipliers found =
      preconditioned_floquet_multipliers(apply, c.inverse(), c.size(), options, nullptr, &vectors);
  const long davidson = products;
  measured("crowd: Davidson's products", static_cast<double>(davidson));
  measured("crowd: Davidson's residual", found.residual);
  CHECK(found.converged);
  CHECK_FALSE(found.complete);
  REQUIRE(found.values.size() == 6);
  const double distance = set_distance(leading(c.spectrum, 6), found.values);
  measured("crowd: Davidson against the known spectrum", distance);
  CHECK(distance <= 1e-9);
  CHECK(found.largest_modulus() == Approx(1.0 - 4e-6).epsilon(1e-12));
  CHECK(found.stable());
  // Sorted as Arnoldi's: decreasing modulus, a pair's positive imaginary part first.
  for (std::size_t i = 0; i + 1 < found.values.size(); ++i) {
    CHECK(std::abs(found.values[i]) >= std::abs(found.values[i + 1]) * (1 - 1e-12));
  }
  CHECK(found.values[0].imag() > 0);
  CHECK(found.values[1] == std::conj(found.values[0]));
  // The Ritz vectors are eigenvectors: |A x − μ x| small, each of unit norm.
  REQUIRE(vectors.cols() == 6);
  double worst_vector = 0.0;
  for (Index i = 0; i < 6; ++i) {
    CHECK(vectors.col(i).norm() == Approx(1.0).epsilon(1e-12));
    const Eigen::VectorXcd r =
        c.A.cast<Complex>() * vectors.col(i) - found.values[static_cast<std::size_t>(i)] * vectors.col(i);
    worst_vector = std::max(worst_vector, r.norm());
  }
  measured("crowd: |A x - mu x| of the Ritz vectors", worst_vector);
  CHECK(worst_vector <= 1e-8);

  // Arnoldi on the same operator, the same count, basis and blocks.
  products = 0;
  const FloquetMultipliers arnoldi = leading_floquet_multipliers(apply, c.size(), options);
  measured("crowd: Arnoldi's products", static_cast<double>(products));
  CHECK(arnoldi.converged);
  CHECK(set_distance(arnoldi.values, found.values) <= 1e-9);
  CHECK(davidson < products);
  const long arnoldi_cold = products;

  // Warm-started from its own Ritz vectors on a nearby operator (the next point of a branch):
  // the same values, in fewer products than from cold.
  const Matrix nearby = c.A * (1.0 + 1e-7);
  products = 0;
  const auto apply_nearby = [&](Matrix& v) {
    products += v.cols();
    v = nearby * v;
  };
  const FloquetMultipliers warm = preconditioned_floquet_multipliers(
      apply_nearby, c.inverse(), c.size(), options, &vectors, nullptr);
  measured("crowd: Davidson's products, warm", static_cast<double>(products));
  CHECK(warm.converged);
  std::vector<Complex> scaled = leading(c.spectrum, 6);
  for (Complex& mu : scaled) mu *= 1.0 + 1e-7;
  CHECK(set_distance(scaled, warm.values) <= 1e-9);
  CHECK(products < davidson);

  // Arnoldi warm-started the same way (from the Schur vectors of the same Ritz vectors): the
  // same values, in fewer products than its own cold start.
  products = 0;
  const FloquetMultipliers arnoldi_warm =
      leading_floquet_multipliers(apply_nearby, c.size(), options, &vectors);
  measured("crowd: Arnoldi's products, warm", static_cast<double>(products));
  CHECK(arnoldi_warm.converged);
  CHECK(set_distance(scaled, arnoldi_warm.values) <= 1e-9);
  CHECK(products < arnoldi_cold);
}

TEST_CASE("the real Schur vectors of leading eigenvectors span their invariant subspaces in order",
          "[orbits]") {
  // A = S D S⁻¹, D: the pair 0.99 e^{±0.3i}, the real 0.98, the pair 0.97 e^{±0.5i}, and 18
  // pairs in a disc of radius 0.5.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Index n = 41;
  Matrix D = Matrix::Zero(n, n);
  put_pair(D, 0, 0.99, 0.3);
  D(2, 2) = 0.98;
  put_pair(D, 3, 0.97, 0.5);
  for (Index i = 5; i + 1 < n; i += 2) put_pair(D, i, 0.5 * std::abs(u(rng)), 3.0 * u(rng));
  const Matrix S = pwl::test::random_basis(n, rng);
  const Matrix A = S * D * S.inverse();

  // The eigenvectors of the five leading values, in the order multipliers are reported (each
  // conjugate with its own column, as the multiplier solvers return them).
  Eigen::EigenSolver<Matrix> eig(A);
  std::vector<Complex> values(eig.eigenvalues().begin(), eig.eigenvalues().end());
  Eigen::MatrixXcd vectors = eig.eigenvectors();
  pwl::orbits::detail::sort_multipliers(values, vectors);
  const Eigen::MatrixXcd leading_five = vectors.leftCols(5);

  const Matrix Q = pwl::orbits::detail::real_schur_vectors(leading_five, 10);
  REQUIRE(Q.cols() == 5);  // a pair's two columns give two vectors, the real value one
  CHECK((Q.transpose() * Q - Matrix::Identity(5, 5)).norm() <= 1e-12);
  const Matrix T = Q.transpose() * A * Q;
  // Invariant: A Q = Q T.
  const double invariance = (A * Q - Q * T).norm() / A.norm();
  measured("Schur vectors: |A Q - Q T| / |A|", invariance);
  CHECK(invariance <= 1e-12);
  // Quasi-upper-triangular, 2 x 2 blocks at 0 and 3: the first two columns span the leading
  // pair's subspace, the first three add the real value's, as a real Schur form's do.
  double below = 0.0;
  for (Index j = 0; j < 5; ++j) {
    for (Index i = j + 1; i < 5; ++i) {
      if (!((i == 1 && j == 0) || (i == 4 && j == 3))) below = std::max(below, std::abs(T(i, j)));
    }
  }
  measured("Schur vectors: largest entry below T's diagonal blocks", below);
  CHECK(below <= 1e-12);
  const auto block_values = [&](Index at) {
    Eigen::EigenSolver<Matrix> block(T.block(at, at, 2, 2), false);
    return std::vector<Complex>(block.eigenvalues().begin(), block.eigenvalues().end());
  };
  CHECK(set_distance(block_values(0), {std::polar(0.99, 0.3), std::polar(0.99, -0.3)}) <= 1e-12);
  CHECK(T(2, 2) == Approx(0.98).epsilon(1e-12));
  CHECK(set_distance(block_values(3), {std::polar(0.97, 0.5), std::polar(0.97, -0.5)}) <= 1e-12);

  // A real multiplier's eigenvector with an imaginary part of rounding size gives one column,
  // not a second made of the rounding.
  Eigen::MatrixXcd rounded = leading_five;
  for (Index i = 0; i < n; ++i) rounded(i, 2) += Complex(0.0, 1e-17 * u(rng));
  CHECK(pwl::orbits::detail::real_schur_vectors(rounded, 10).cols() == 5);

  // At most `limit` columns, the leading ones; nothing from a non-finite set.
  const Matrix first_three = pwl::orbits::detail::real_schur_vectors(leading_five, 3);
  REQUIRE(first_three.cols() == 3);
  CHECK((first_three - Q.leftCols(3)).norm() <= 1e-14);
  Eigen::MatrixXcd broken = leading_five;
  broken(7, 2) = Complex(std::numeric_limits<double>::quiet_NaN(), 0.0);
  CHECK(pwl::orbits::detail::real_schur_vectors(broken, 10).cols() == 0);
}

TEST_CASE("preconditioned Davidson reports every multiplier in a band round the circle, or says "
          "it did not",
          "[orbits]") {
  // Arnoldi's band test: (1 − 4e-5 k²) e^{±0.03 k i}, k = 1 .. 100, in 400 dimensions, the
  // rest in a disc of radius 0.5.
  ArnoldiOptions options;
  options.count = 6;
  const auto run = [&](const Case& c, double margin) {
    options.margin = margin;
    return preconditioned_floquet_multipliers([&c](Matrix& v) { v = c.A * v; }, c.inverse(),
                                              c.size(), options);
  };
  {
    std::mt19937 rng(5);
    const Case c = crowd(400, 100, 4e-5, 0.03, 0.5, rng);
    // Margin 0.01: the 15 pairs of |μ| > 0.99, all of them, and the smallest below the band.
    const FloquetMultipliers found = run(c, 0.01);
    const std::vector<Complex> band = in_band(c.spectrum, 0.99);
    REQUIRE(band.size() == 30);
    CHECK(found.converged);
    CHECK(found.band_covered);
    CHECK(found.values.size() >= 30);
    CHECK(std::abs(found.values.back()) <= 0.99);
    const double worst = farthest(band, found.values);
    measured("band of 0.01: farthest multiplier of the band from a reported one", worst);
    CHECK(worst <= 1e-9);
    // Margin 0.2 with a basis of 200: 140 in the band, more than half the basis holds: said so.
    options.davidson_dimension = 200;
    const FloquetMultipliers wide = run(c, 0.2);
    options.davidson_dimension = ArnoldiOptions{}.davidson_dimension;
    REQUIRE(in_band(c.spectrum, 0.8).size() == 140);
    CHECK_FALSE(wide.band_covered);
    CHECK(wide.values.size() < 140);
  }
  {
    // Five pairs pushed outside the circle, no margin: all ten outside reported.
    std::mt19937 rng(5);
    const Case c = crowd(400, 100, 4e-5, 0.03, 0.5, rng, 5, 1.01);
    const FloquetMultipliers found = run(c, 0.0);
    const std::vector<Complex> outside = in_band(c.spectrum, 1.0);
    REQUIRE(outside.size() == 10);
    CHECK(found.converged);
    CHECK(found.band_covered);
    CHECK(farthest(outside, found.values) <= 1e-9);
    CHECK(found.unstable_count() == 10);
  }
}

TEST_CASE("on an operator its basis spans, preconditioned Davidson reports the whole band at once",
          "[orbits]") {
  // 24 dimensions, a basis of 200: the space fills, every Ritz value is exact, and every value of
  // the band (|μ| > 0.5: here 12 of them) is reported, the six asked for or not.
  std::mt19937 rng(3);
  const Case c = crowd(24, 6, 0.01, 0.4, 0.45, rng);
  ArnoldiOptions options;
  options.count = 2;
  options.margin = 0.5;
  const FloquetMultipliers found = preconditioned_floquet_multipliers(
      [&c](Matrix& v) { v = c.A * v; }, c.inverse(), c.size(), options);
  const std::vector<Complex> band = in_band(c.spectrum, 0.5);
  REQUIRE(band.size() == 12);
  CHECK(found.converged);
  CHECK(found.band_covered);
  CHECK(found.values.size() >= band.size());
  CHECK(farthest(band, found.values) <= 1e-10);
  // And with everything asked for: all 24, complete.
  options.count = 24;
  const FloquetMultipliers all = preconditioned_floquet_multipliers(
      [&c](Matrix& v) { v = c.A * v; }, c.inverse(), c.size(), options);
  CHECK(all.complete);
  REQUIRE(all.values.size() == 24);
  CHECK(set_distance(c.spectrum, all.values) <= 1e-10);
}

TEST_CASE("preconditioned Davidson refuses what it cannot use", "[orbits]") {
  ArnoldiOptions options;
  const auto apply = [](Matrix&) {};
  const ShiftedInverse none;
  CHECK_THROWS_WITH(preconditioned_floquet_multipliers(apply, none, 10, options),
                    Catch::Contains("no shifted inverse"));
  const ShiftedInverse identity = [](const Eigen::VectorXcd& r, Complex) { return r; };
  CHECK_THROWS_WITH(preconditioned_floquet_multipliers(apply, identity, 0, options),
                    Catch::Contains("operator size = 0"));
  options.davidson_dimension = 6;
  CHECK_THROWS_WITH(preconditioned_floquet_multipliers(apply, identity, 10, options),
                    Catch::Contains("davidson dimension = 6"));
  options.count = 0;
  CHECK_THROWS_WITH(preconditioned_floquet_multipliers(apply, identity, 10, options),
                    Catch::Contains("floquet count = 0"));
}
