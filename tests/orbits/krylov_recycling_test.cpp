// GMRES with a recycled subspace (GCRO-DR, Parks et al. 2006; analysis/src/orbits/gmres.hpp)
// against an LU solve of the same dense systems: a sequence of slowly changing operators with a
// few small eigenvalues (the directions GMRES is slowest to find), several right-hand sides of one
// operator, and the space kept between them. The recycled space must hold C = A U orthonormal, must
// approach the eigenvectors of the smallest eigenvalues, must cost fewer products than plain GMRES
// on one operator, and with no space kept the solver must be GMRES, bit for bit. The drifting
// sequence re-forms A U for each operator (the paper's method); by default a new operator drops
// the space.
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "orbits/gmres.hpp"

using namespace pwl;
using pwl::orbits::detail::gmres;
using pwl::orbits::detail::GmresResult;
using pwl::orbits::detail::RecycledSubspace;

namespace {

// A = S Λ S⁻¹ with S near the identity: eigenvalues spread over [1, 4] but for `small` of them
// in [2e-3, 2e-2], and a drift `t` that moves every eigenvalue by a few percent.
struct Operators {
  Matrix S, S_inverse;
  Vector lambda;
  Matrix at(double t) const {
    Vector l = lambda * (1.0 + 0.05 * t);
    return S * l.asDiagonal() * S_inverse;
  }
};

Operators operators(Index n, Index small, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Operators o;
  o.S = Matrix::Identity(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < n; ++j) o.S(i, j) += 0.3 * u(rng) / std::sqrt(double(n));
  o.S_inverse = o.S.inverse();
  o.lambda.resize(n);
  for (Index i = 0; i < n; ++i) {
    o.lambda(i) = i < small ? 2e-3 * (1.0 + 9.0 * double(i) / double(small))
                            : 2.5 + 1.5 * u(rng);
  }
  return o;
}

Vector random_vector(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> z;
  Vector v(n);
  for (Index i = 0; i < n; ++i) v(i) = z(rng);
  return v;
}

GmresResult solve(const Matrix& A, const Vector& b, Vector& x, RecycledSubspace* space,
                  int dimension = 30, int restarts = 40) {
  return gmres([&](const Vector& v) -> Vector { return A * v; }, b, x, 1e-10, dimension, restarts,
               space);
}

// Restarted GMRES as pwl had it before recycling (the same operations in the same order): the
// reference for "with no space kept it is GMRES, bit for bit".
GmresResult reference_gmres(const Matrix& A, const Vector& b, Vector& x, double tolerance,
                            int dimension, int restarts) {
  GmresResult result;
  const Index n = b.size();
  x = Vector::Zero(n);
  const double b_norm = b.norm();
  Vector r = b;
  for (int cycle = 0; cycle <= restarts; ++cycle) {
    const double beta = r.norm();
    result.relative_residual = beta / b_norm;
    if (result.relative_residual <= tolerance) return result;
    const int m = static_cast<int>(std::min<Index>(dimension, n));
    Matrix V = Matrix::Zero(n, m + 1);
    Matrix H = Matrix::Zero(m + 1, m);
    std::vector<double> cs(m), sn(m);
    Vector g = Vector::Zero(m + 1);
    g(0) = beta;
    V.col(0) = r / beta;
    int used = 0;
    for (int j = 0; j < m; ++j) {
      Vector w = A * V.col(j);
      ++result.products;
      for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i <= j; ++i) {
          const double h = V.col(i).dot(w);
          H(i, j) += h;
          w -= h * V.col(i);
        }
      }
      H(j + 1, j) = w.norm();
      if (H(j + 1, j) > 0) V.col(j + 1) = w / H(j + 1, j);
      for (int i = 0; i < j; ++i) {
        const double t = cs[i] * H(i, j) + sn[i] * H(i + 1, j);
        H(i + 1, j) = -sn[i] * H(i, j) + cs[i] * H(i + 1, j);
        H(i, j) = t;
      }
      const double denom = std::hypot(H(j, j), H(j + 1, j));
      cs[j] = denom == 0 ? 1.0 : H(j, j) / denom;
      sn[j] = denom == 0 ? 0.0 : H(j + 1, j) / denom;
      H(j, j) = denom;
      H(j + 1, j) = 0;
      g(j + 1) = -sn[j] * g(j);
      g(j) = cs[j] * g(j);
      used = j + 1;
      if (std::abs(g(j + 1)) / b_norm <= tolerance || H(j, j) == 0) break;
    }
    const Vector y = H.topLeftCorner(used, used).triangularView<Eigen::Upper>().solve(g.head(used));
    x += V.leftCols(used) * y;
    r = b - A * x;
    ++result.products;
    result.relative_residual = r.norm() / b_norm;
  }
  return result;
}

// The largest sine of the principal angles between span X and span Y.
double subspace_gap(const Matrix& X, const Matrix& Y) {
  const Matrix Qx = Eigen::HouseholderQR<Matrix>(X).householderQ() *
                    Matrix::Identity(X.rows(), X.cols());
  const Matrix Qy = Eigen::HouseholderQR<Matrix>(Y).householderQ() *
                    Matrix::Identity(Y.rows(), Y.cols());
  return (Qy - Qx * (Qx.transpose() * Qy)).norm() / std::sqrt(double(Y.cols()));
}

}  // namespace

TEST_CASE("recycled GMRES solves a drifting sequence of systems as LU does") {
  const Index n = 200;
  const Operators o = operators(n, 6, 7u);
  RecycledSubspace space(10, true);  // C = A U formed again for each new operator
  for (int i = 0; i < 8; ++i) {
    const Matrix A = o.at(0.1 * i);
    const Vector b = random_vector(n, 100u + unsigned(i));
    space.operator_changed();
    Vector x;
    const GmresResult g = solve(A, b, x, &space);
    const Vector exact = A.partialPivLu().solve(b);
    INFO("system " << i << ", products " << g.products);
    CHECK(g.relative_residual <= 1e-10);
    CHECK((b - A * x).norm() <= 1.01e-10 * b.norm());
    CHECK((x - exact).norm() <= 1e-6 * exact.norm());
    // The space's defining relation for this operator: C orthonormal, A U = C.
    REQUIRE(space.U.cols() > 0);
    REQUIRE(space.U.cols() <= 10);
    CHECK((space.C.transpose() * space.C - Matrix::Identity(space.C.cols(), space.C.cols()))
              .norm() <= 1e-12);
    CHECK((A * space.U - space.C).norm() <= 1e-9 * space.C.norm());
  }
  // Without re-forming, a new operator drops the space.
  RecycledSubspace dropped(10);
  Vector x;
  solve(o.at(0.0), random_vector(n, 5u), x, &dropped);
  REQUIRE(dropped.U.cols() > 0);
  dropped.operator_changed();
  CHECK(dropped.U.size() == 0);
  CHECK_FALSE(dropped.current);
}

TEST_CASE("on one operator the recycled space costs fewer products than GMRES") {
  const Index n = 200;
  const Operators o = operators(n, 6, 11u);
  const Matrix A = o.at(0.0);
  RecycledSubspace space(10);
  int plain = 0, recycled = 0;
  for (int i = 0; i < 6; ++i) {
    const Vector b = random_vector(n, 300u + unsigned(i));
    const Vector exact = A.partialPivLu().solve(b);
    Vector x0, x1;
    const GmresResult g0 = solve(A, b, x0, nullptr);
    const GmresResult g1 = solve(A, b, x1, &space);
    INFO("right-hand side " << i << ": GMRES " << g0.products << ", recycled " << g1.products);
    CHECK(g0.relative_residual <= 1e-10);
    CHECK(g1.relative_residual <= 1e-10);
    CHECK((x1 - exact).norm() <= 1e-6 * exact.norm());
    if (i > 0) {
      plain += g0.products;
      recycled += g1.products;
    }
  }
  if (std::getenv("PWL_TEST_VERBOSE") != nullptr) {
    std::printf("products over 5 warm right-hand sides: GMRES %d, recycled %d\n", plain,
                recycled);
  }
  CHECK(recycled < plain * 0.7);
  // Still C = A U after six solves on the one operator.
  CHECK((A * space.U - space.C).norm() <= 1e-9 * space.C.norm());
  // What it kept: the invariant subspace of the six smallest eigenvalues (S's first six columns).
  CHECK(subspace_gap(space.U, o.S.leftCols(6)) <= 1e-4);
}

TEST_CASE("with no space kept recycled GMRES is GMRES, bit for bit") {
  const Index n = 120;
  const Operators o = operators(n, 4, 5u);
  const Matrix A = o.at(0.3);
  const Vector b = random_vector(n, 9u);
  // Restarted (cycles of 20): no space given, or a space of size 0.
  Vector xr;
  const GmresResult reference = reference_gmres(A, b, xr, 1e-10, 20, 30);
  REQUIRE(reference.products > 21);  // it restarted
  RecycledSubspace none(0);
  Vector x0, x1;
  const GmresResult g0 = solve(A, b, x0, nullptr, 20, 30);
  const GmresResult g1 = solve(A, b, x1, &none, 20, 30);
  for (const auto* g : {&g0, &g1}) {
    CHECK(g->products == reference.products);
    CHECK(g->relative_residual == reference.relative_residual);
  }
  CHECK((x0 - xr).cwiseAbs().maxCoeff() == 0.0);
  CHECK((x1 - xr).cwiseAbs().maxCoeff() == 0.0);
  // A space asked for but still empty, on a solve that converges in its first cycle: that cycle
  // is GMRES's (the space is only built from it afterwards).
  RecycledSubspace fresh(10);
  Vector xf, xg;
  const GmresResult first = solve(A, b, xf, &fresh, 60, 0);
  const GmresResult plain = reference_gmres(A, b, xg, 1e-10, 60, 0);
  REQUIRE(plain.relative_residual <= 1e-10);
  CHECK(first.products == plain.products);
  CHECK((xf - xg).cwiseAbs().maxCoeff() == 0.0);
  CHECK(fresh.U.cols() == 10);
}

TEST_CASE("complex small eigenvalues: their real invariant subspace is recycled") {
  // Three pairs of small complex eigenvalues (2 x 2 rotation blocks of modulus 3e-3 to 1.2e-2)
  // among real ones in [1, 4]: the harmonic Ritz pairs are complex, kept by their real and
  // imaginary parts. Over eight right-hand sides of the one operator, A U = C must hold after
  // every solve, and the space must become the pairs' real invariant subspace.
  const Index n = 160;
  Operators o = operators(n, 0, 21u);
  Matrix L = o.lambda.asDiagonal();
  for (int pair = 0; pair < 3; ++pair) {
    const double radius = 3e-3 * (1 + 1.5 * pair), angle = 0.4 + 0.7 * pair;
    const Index i = 2 * pair;
    L(i, i) = L(i + 1, i + 1) = radius * std::cos(angle);
    L(i, i + 1) = radius * std::sin(angle);
    L(i + 1, i) = -radius * std::sin(angle);
  }
  const Matrix A = o.S * L * o.S_inverse;
  RecycledSubspace space(8);
  int plain = 0, recycled = 0;
  for (int i = 0; i < 8; ++i) {
    const Vector b = random_vector(n, 700u + unsigned(i));
    Vector x0, x1;
    const GmresResult g0 = solve(A, b, x0, nullptr);
    const GmresResult g1 = solve(A, b, x1, &space);
    INFO("right-hand side " << i << ": GMRES " << g0.products << ", recycled " << g1.products);
    CHECK(g1.relative_residual <= 1e-10);
    CHECK((b - A * x1).norm() <= 1.01e-10 * b.norm());
    REQUIRE(space.U.cols() > 0);
    CHECK((space.C.transpose() * space.C - Matrix::Identity(space.C.cols(), space.C.cols()))
              .norm() <= 1e-12);
    CHECK((A * space.U - space.C).norm() <= 1e-9 * space.C.norm());
    if (i > 0) {
      plain += g0.products;
      recycled += g1.products;
    }
  }
  CHECK(recycled < plain * 0.7);
  CHECK(subspace_gap(space.U, o.S.leftCols(6)) <= 1e-4);
}

TEST_CASE("a space as large as the system solves at once and then needs no product") {
  // Every vector of a 12-dimensional system recycled after one solve (k = 11 of 12): the next
  // right-hand side of the same operator is solved by the projection alone up to one direction.
  const Index n = 12;
  const Operators o = operators(n, 2, 3u);
  const Matrix A = o.at(0.0);
  RecycledSubspace space(11);
  Vector x;
  solve(A, random_vector(n, 1u), x, &space, 12, 5);
  const Vector b = random_vector(n, 2u);
  const GmresResult g = solve(A, b, x, &space, 12, 5);
  CHECK(g.relative_residual <= 1e-10);
  CHECK((x - A.partialPivLu().solve(b)).norm() <= 1e-8 * x.norm());
  CHECK(g.products <= 3);
}
