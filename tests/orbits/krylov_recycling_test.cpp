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
#include <random>

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
  // What it kept: the invariant subspace of the six smallest eigenvalues (S's first six columns).
  CHECK(subspace_gap(space.U, o.S.leftCols(6)) <= 1e-4);
}

TEST_CASE("with no space kept recycled GMRES is GMRES, bit for bit") {
  const Index n = 120;
  const Operators o = operators(n, 4, 5u);
  const Matrix A = o.at(0.3);
  const Vector b = random_vector(n, 9u);
  RecycledSubspace none(0);
  Vector x0, x1;
  const GmresResult g0 = solve(A, b, x0, nullptr, 20, 30);
  const GmresResult g1 = solve(A, b, x1, &none, 20, 30);
  CHECK(g0.products == g1.products);
  CHECK(g0.relative_residual == g1.relative_residual);
  CHECK((x0 - x1).cwiseAbs().maxCoeff() == 0.0);
  CHECK(none.U.size() == 0);
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
