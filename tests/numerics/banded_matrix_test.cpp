// BandedMatrix against dense Eigen arithmetic: storage, shared rows, products.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>

#include <omp.h>

#include "pwl/numerics/banded_matrix.hpp"
#include "pwl/errors.hpp"
#include "pwl/model/gap_structure.hpp"

using namespace pwl;

namespace {

Matrix random_banded(Index rows, Index cols, Index lower, Index upper, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix A = Matrix::Zero(rows, cols);
  for (Index i = 0; i < rows; ++i) {
    for (Index j = std::max<Index>(0, i - lower); j <= std::min(cols - 1, i + upper); ++j) {
      A(i, j) = u(rng);
    }
  }
  return A;
}

Vector random_vector(Index n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector v(n);
  for (Index i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

double max_abs(const Matrix& A) { return A.size() ? A.cwiseAbs().maxCoeff() : 0.0; }

}  // namespace

TEST_CASE("A banded matrix keeps exactly the band of a dense matrix", "[banded]") {
  std::mt19937 rng(1);
  const Matrix A = Matrix::Random(30, 30);
  for (Index hw : {0, 1, 3, 10, 40}) {
    const BandedMatrix B = BandedMatrix::from_dense(A, hw);
    Matrix expected = A;
    for (Index i = 0; i < 30; ++i)
      for (Index j = 0; j < 30; ++j)
        if (std::abs(i - j) > hw) expected(i, j) = 0.0;
    INFO("half width " << hw);
    CHECK(max_abs(B.to_dense() - expected) == 0.0);
    CHECK(B.width() == std::min<Index>(30, 2 * hw + 1));
    for (Index i = 0; i < 30; i += 7)
      for (Index j = 0; j < 30; j += 3) CHECK(B.coeff(i, j) == expected(i, j));
  }
  const Matrix C = random_banded(25, 25, 2, 4, rng);
  const BandedMatrix D = BandedMatrix::from_dense_nonzeros(C);
  CHECK(max_abs(D.to_dense() - C) == 0.0);
  CHECK(D.lower_bandwidth() == 2);
  CHECK(D.upper_bandwidth() == 4);
}

TEST_CASE("Banded products equal dense products for fixed and run-time widths", "[banded]") {
  std::mt19937 rng(2);
  // Widths 1 and 11 use the compile-time kernels, 81 (> 64) the run-time loop; 0 rows and a
  // rectangular matrix are covered too.
  for (auto [rows, cols, lower, upper] :
       std::vector<std::array<Index, 4>>{{40, 40, 0, 0}, {50, 50, 5, 5}, {100, 100, 40, 40},
                                         {60, 30, 3, 2}, {0, 5, 1, 1}}) {
    const Matrix A = random_banded(rows, cols, lower, upper, rng);
    const BandedMatrix B = BandedMatrix::from_dense_nonzeros(A);
    const Vector x = random_vector(cols, rng);
    Vector y = random_vector(rows, rng);
    const Vector y0 = y;
    INFO(rows << "x" << cols << " width " << B.width());
    const Vector product = B * x;
    REQUIRE(product.size() == rows);
    B.multiply_add(x.data(), y.data());
    if (rows > 0) {
      CHECK((product - A * x).cwiseAbs().maxCoeff() <= 1e-13 * (1 + cols));
      CHECK((y - y0 - A * x).cwiseAbs().maxCoeff() <= 1e-13 * (1 + cols));
    }
    // The listed rows only, in any order and with repeats, as the LCP's sweeps ask for them.
    std::vector<int> listed;
    for (Index i = rows - 1; i >= 0; i -= 3) listed.push_back(static_cast<int>(i));
    if (rows > 0) listed.push_back(0);
    std::vector<double> some(listed.size(), 99.0);
    B.multiply_listed_rows(x.data(), listed.data(), static_cast<Index>(listed.size()), some.data());
    for (std::size_t c = 0; c < listed.size(); ++c) {
      CHECK(std::abs(some[c] - A.row(listed[c]).dot(x)) <= 1e-13 * (1 + cols));
    }
  }
  CHECK_THROWS_AS(BandedMatrix::from_dense(Matrix::Identity(3, 3), 1) * Vector::Ones(4),
                  InputError);
}

TEST_CASE("Identical rows are stored once and shifted rows stay correct", "[banded]") {
  // A Toeplitz band: every interior row is the same row shifted.
  const Index n = 200;
  Matrix A = Matrix::Zero(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index d = -3; d <= 3; ++d)
      if (i + d >= 0 && i + d < n) A(i, i + d) = 1.0 / (2 + d + 3 * (d < 0));
  const BandedMatrix shared = BandedMatrix::from_dense(A, 3);
  BandedMatrixBuilder plain_builder(n, n, 7, /*share_rows=*/false);
  for (Index i = 0; i < n; ++i) {
    const Index lo = std::max<Index>(0, i - 3), hi = std::min(n, i + 4);
    std::vector<double> row;
    for (Index j = lo; j < hi; ++j) row.push_back(A(i, j));
    plain_builder.set_row(i, lo, row.data(), hi - lo);
  }
  const BandedMatrix plain = plain_builder.build();
  // Interior rows share one stored row; the 3 rows at each end differ. Both storages describe
  // their rows with a few periodic segments (the plain one's stored row advances with the row).
  CHECK(shared.stored_rows() == 7);
  CHECK(plain.stored_rows() == n);
  CHECK(shared.segments() <= 7);
  CHECK(plain.segments() <= 7);
  CHECK(shared.memory_bytes() < plain.memory_bytes() / 4);
  CHECK(max_abs(shared.to_dense() - A) == 0.0);
  CHECK(max_abs(plain.to_dense() - A) == 0.0);
  std::mt19937 rng(3);
  const Vector x = random_vector(n, rng);
  CHECK((shared * x - A * x).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("Products with sparse matrices, diagonal shifts and row selection", "[banded]") {
  std::mt19937 rng(4);
  const Matrix A = random_banded(40, 30, 4, 3, rng);
  const BandedMatrix B = BandedMatrix::from_dense_nonzeros(A);
  // A sparse, banded right factor (30 x 20) and a left one (25 x 40).
  Matrix R = Matrix::Zero(30, 20);
  for (Index i = 0; i < 30; ++i) R(i, std::min<Index>(19, i * 2 / 3)) = 1.0 + 0.1 * static_cast<double>(i);
  Matrix L = Matrix::Zero(25, 40);
  for (Index j = 0; j < 25; ++j) {
    L(j, j) = -2.0;
    L(j, j + 1) = 0.5;
  }
  const BandedMatrix BR = multiply(B, to_sparse(R));
  const BandedMatrix LB = multiply(to_sparse(L), B);
  CHECK(max_abs(BR.to_dense() - A * R) < 1e-14);
  CHECK(max_abs(LB.to_dense() - L * A) < 1e-14);
  const Matrix S = random_banded(30, 30, 2, 0, rng);
  const Vector d = random_vector(30, rng);
  CHECK(max_abs(add_diagonal(BandedMatrix::from_dense_nonzeros(S), d).to_dense() -
                (S + Matrix(d.asDiagonal()))) == 0.0);
  const BandedMatrix even = select_rows(B, 0, 2);
  REQUIRE(even.rows() == 20);
  for (Index r = 0; r < 20; ++r) CHECK((even.to_dense().row(r) - A.row(2 * r)).cwiseAbs().maxCoeff() == 0.0);
  CHECK_THROWS_AS(multiply(B, to_sparse(Matrix::Ones(5, 5))), InputError);
  // The band of a sparse matrix's stored non-zeros: the same matrix, the band as narrow as the
  // widest row needs (explicit zeros left out).
  for (const Matrix& D : {A, R, L, S}) {
    SparseMatrix sparse = to_sparse(D);
    const BandedMatrix from_sparse = BandedMatrix::from_sparse_nonzeros(sparse);
    CHECK(max_abs(from_sparse.to_dense() - D) == 0.0);
    CHECK(from_sparse.width() == BandedMatrix::from_dense_nonzeros(D).width());
  }
  SparseMatrix with_zero = to_sparse(Matrix::Identity(4, 6));
  with_zero.coeffRef(0, 5) = 0.0;  // stored, but zero
  CHECK(BandedMatrix::from_sparse_nonzeros(with_zero).width() == 1);
}

TEST_CASE("Stencil and row-wise products agree to rounding", "[banded]") {
  // A chain-like operator: boundary rows of their own, then one row repeated one column further
  // each row (a Toeplitz band, applied as a stencil when stored once), for widths 1 to 8 and
  // both products. The same matrix with every row stored takes the row-wise path.
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Index width = 1; width <= 8; ++width) {
    const Index rows = 300, cols = rows + width;
    std::vector<double> interior(static_cast<std::size_t>(width)), row(interior.size());
    for (double& v : interior) v = u(rng);
    BandedMatrixBuilder shared(rows, cols, width, true), every(rows, cols, width, false);
    for (Index i = 0; i < rows; ++i) {
      const bool boundary = i < 3 || i >= rows - 4;
      for (std::size_t k = 0; k < row.size(); ++k) row[k] = boundary ? u(rng) : interior[k];
      shared.set_row(i, i, row.data(), width);
      every.set_row(i, i, row.data(), width);
    }
    const BandedMatrix stencil = shared.build(), row_wise = every.build();
    REQUIRE(stencil.stored_rows() <= 8);
    REQUIRE(row_wise.stored_rows() == rows);
    const Vector x = random_vector(cols, rng), y0 = random_vector(rows, rng);
    const Matrix D = stencil.to_dense();
    Vector a(rows), b(rows), c = y0, d = y0;
    stencil.multiply(x.data(), a.data());
    row_wise.multiply(x.data(), b.data());
    stencil.multiply_add(x.data(), c.data());
    row_wise.multiply_add(x.data(), d.data());
    const double scale = static_cast<double>(width) * 4.0 * std::numeric_limits<double>::epsilon();
    INFO("width " << width);
    CHECK((a - b).cwiseAbs().maxCoeff() <= scale);
    CHECK((a - D * x).cwiseAbs().maxCoeff() <= scale);
    CHECK((c - d).cwiseAbs().maxCoeff() <= 2.0 * scale);
    CHECK((c - (y0 + D * x)).cwiseAbs().maxCoeff() <= 2.0 * scale);
  }
}

TEST_CASE("Products over 10^5 rows and more give the one-thread result to the bit", "[banded][threads]") {
  // 250000 rows, every row stored (random values), so that the row blocks of the threads cross
  // segment boundaries anywhere.
  const Index rows = 250000, cols = 250000, width = 7;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BandedMatrixBuilder builder(rows, cols, width, false);
  std::vector<double> row(static_cast<std::size_t>(width));
  for (Index i = 0; i < rows; ++i) {
    for (double& v : row) v = u(rng);
    builder.set_row(i, std::clamp<Index>(i - width / 2, 0, cols - width), row.data(), width);
  }
  const BandedMatrix A = builder.build();
  const Vector x = random_vector(cols, rng), y0 = random_vector(rows, rng);
  const auto products = [&](int threads) {
    omp_set_num_threads(threads);
    Vector y(rows), z = y0, w = y0;
    A.multiply(x.data(), y.data());
    A.multiply_add(x.data(), z.data());
    const double largest = A.multiply_add_max_abs(x.data(), w.data());
    return std::make_tuple(y, z, w, largest);
  };
  const int threads = std::max(2, omp_get_max_threads());
  const auto [y1, z1, w1, m1] = products(1);
  const auto [y2, z2, w2, m2] = products(threads);
  omp_set_num_threads(threads);
  CHECK((y1 - y2).cwiseAbs().maxCoeff() == 0.0);
  CHECK((z1 - z2).cwiseAbs().maxCoeff() == 0.0);
  CHECK((w1 - w2).cwiseAbs().maxCoeff() == 0.0);
  CHECK(m1 == m2);
  CHECK(m1 == w1.cwiseAbs().maxCoeff());
  // A NaN in the last row is reported as infinity whichever thread meets it.
  Vector bad = x;
  bad[cols - 1] = std::numeric_limits<double>::quiet_NaN();
  Vector v = y0;
  CHECK(std::isinf(A.multiply_add_max_abs(bad.data(), v.data())));
}

TEST_CASE("The builder rejects runs outside the matrix and unset rows", "[banded]") {
  BandedMatrixBuilder b(4, 6, 3);
  const double v[3] = {1, 2, 3};
  CHECK_THROWS_AS(b.set_row(0, 5, v, 3), InputError);   // columns 5..7 of 6
  CHECK_THROWS_AS(b.set_row(0, -1, v, 2), InputError);
  CHECK_THROWS_AS(b.set_row(4, 0, v, 3), InputError);   // row 4 of 4
  CHECK_THROWS_AS(b.set_row(0, 0, v, 4), InputError);   // wider than the band
  b.set_row(0, 0, v, 3);
  CHECK_THROWS_AS(b.build(), Error);                    // rows 1..3 never set
  // A run that starts near the right edge is shifted inside; the entries it gains are zero.
  BandedMatrixBuilder c(1, 6, 3);
  c.set_row(0, 5, v, 1);
  const BandedMatrix m = c.build();
  CHECK(m.first_column(0) == 3);
  CHECK(m.coeff(0, 5) == 1.0);
  CHECK(m.coeff(0, 3) == 0.0);
  CHECK(m.coeff(0, 4) == 0.0);
}

TEST_CASE("Products over row ranges, with a bound check, and by listed columns", "[banded]") {
  std::mt19937 rng(5);
  // An interleaved-state-like operator: rows in pairs sharing a run that moves by 2 per pair.
  const Index n = 300;
  Matrix A = Matrix::Zero(2 * n, 2 * n);
  const Matrix pattern = Matrix::Random(2, 10);
  for (Index i = 0; i < n; ++i)
    for (int a = 0; a < 2; ++a)
      for (Index k = 0; k < 10; ++k) {
        const Index j = 2 * (i - 2) + k;
        if (j >= 0 && j < 2 * n) A(2 * i + a, j) = pattern(a, k);
      }
  const BandedMatrix B = BandedMatrix::from_dense_nonzeros(A);
  CHECK(B.segments() < 20);  // pairs of rows repeat: period 2
  const Vector x = random_vector(2 * n, rng);
  const Vector full = A * x;
  Vector y = Vector::Constant(2 * n, 7.0);
  for (Index r0 = 0; r0 < 2 * n; r0 += 77) B.multiply(x.data(), y.data(), r0, std::min<Index>(2 * n, r0 + 77));
  CHECK((y - full).cwiseAbs().maxCoeff() < 1e-13);
  Vector z = Vector::Ones(2 * n);
  B.multiply_add(x.data(), z.data(), 10, 31);
  CHECK((z.segment(10, 21) - full.segment(10, 21) - Vector::Ones(21)).cwiseAbs().maxCoeff() < 1e-13);
  CHECK(z[9] == 1.0);
  CHECK(z[31] == 1.0);
  CHECK_THROWS_AS(B.multiply(x.data(), y.data(), 5, 2 * n + 1), InputError);
  // y += A x with max |y|, over everything and over a range; infinity for a non-finite entry.
  Vector w = Vector::Ones(2 * n);
  const double largest = B.multiply_add_max_abs(x.data(), w.data());
  CHECK((w - full - Vector::Ones(2 * n)).cwiseAbs().maxCoeff() < 1e-13);
  CHECK(largest == Approx((full + Vector::Ones(2 * n)).cwiseAbs().maxCoeff()).epsilon(1e-15));
  Vector u = Vector::Zero(2 * n);
  const double part = B.multiply_add_max_abs(x.data(), u.data(), 100, 200);
  CHECK(part == Approx(full.segment(100, 100).cwiseAbs().maxCoeff()).epsilon(1e-15));
  Vector bad = Vector::Zero(2 * n);
  bad[50] = std::numeric_limits<double>::quiet_NaN();
  CHECK(std::isinf(B.multiply_add_max_abs(x.data(), bad.data())));
  // Transposes: y += A^T x by all rows and by the listed non-zeros of x.
  const BandedMatrix T = transpose(B);
  CHECK(max_abs(T.to_dense() - A.transpose()) == 0.0);
  Vector sparse = Vector::Zero(2 * n);
  std::vector<int> listed{3, 40, 41, 599};
  for (int i : listed) sparse[i] = 1.0 + i;
  Vector t1 = Vector::Zero(2 * n), t2 = Vector::Zero(2 * n);
  B.transpose_multiply_add(sparse.data(), t1.data());
  B.transpose_multiply_add(sparse.data(), listed.data(), static_cast<Index>(listed.size()), t2.data());
  const Vector expected = A.transpose() * sparse;
  CHECK((t1 - expected).cwiseAbs().maxCoeff() < 1e-13);
  CHECK((t2 - expected).cwiseAbs().maxCoeff() < 1e-13);
}

namespace {

// A rectangular operator of a chain of `cells` cells: 2 rows per cell (interleaved state), 3
// columns per cell (springs), band from the cell's columns; rows repeat with the cell except in
// the first 4 and the last 3 cells, whose entries depend on the distance to the end.
Matrix periodic_operator(Index cells) {
  Matrix A = Matrix::Zero(2 * cells, 3 * cells);
  for (Index c = 0; c < cells; ++c) {
    for (Index a = 0; a < 2; ++a) {
      for (Index j = std::max<Index>(0, 3 * (c - 2)); j < std::min<Index>(3 * cells, 3 * (c + 3)); ++j) {
        double v = std::sin(1.0 + 3.0 * a + 0.7 * static_cast<double>(j - 3 * c));
        if (c < 4) v += 0.1 * static_cast<double>(4 - c);
        if (c >= cells - 3) v -= 0.05 * static_cast<double>(c - cells + 4);
        A(2 * c + a, j) = v;
      }
    }
  }
  return A;
}

}  // namespace

TEST_CASE("Repeating a period of rows lays out the longer operator exactly", "[banded][period]") {
  // The short operator of 20 cells with periods of cells 9..10 inserted 7 times at cell 10 is the
  // operator of 34 cells (a 2-cell period: two copies of 2 cells of rows each... here one cell
  // repeats, so a period of 2 cells is also a period).
  const Index short_cells = 20, cut = 10, period = 2, copies = 7;
  const BandedMatrix A = BandedMatrix::from_dense_nonzeros(periodic_operator(short_cells));
  const AxisRepeat rows{2 * cut, 2 * period, copies}, cols{3 * cut, 3 * period, copies};
  const BandedMatrix B = repeat_period(A, rows, cols);
  const Matrix expected = periodic_operator(short_cells + period * copies);
  REQUIRE(B.rows() == expected.rows());
  REQUIRE(B.cols() == expected.cols());
  CHECK((B.to_dense() - expected).cwiseAbs().maxCoeff() == 0.0);
  // No row computed or stored again; products over the segments read the layout.
  CHECK(B.stored_rows() == A.stored_rows());
  const Vector x = Vector::LinSpaced(B.cols(), -1.0, 2.0);
  CHECK((B * x - expected * x).cwiseAbs().maxCoeff() <= 1e-14);
  // An axis without rows in the period (no spring in the repeated cells) inserts nothing.
  const BandedMatrix C = repeat_period(A, {2 * cut, 0, copies}, {3 * cut, 3 * period, copies});
  CHECK(C.rows() == A.rows());
  CHECK(C.cols() == A.cols() + 3 * period * copies);
  // A period that does not fit before the cut is refused.
  CHECK_THROWS_AS(repeat_period(A, {2, 4, 1}, {3, 6, 1}), Error);
}
