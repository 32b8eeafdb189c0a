// Tests of the LCP solvers against independent truth: exhaustive enumeration of complementary
// bases, closed-form solutions, and the solvers against each other.
#include "pwl/numerics/lcp_solver.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "pwl/errors.hpp"

namespace {

using pwl::Index;
using pwl::Matrix;
using pwl::Vector;

constexpr double kInf = std::numeric_limits<double>::infinity();

double inf_norm(const Vector& v) { return v.size() ? v.lpNorm<Eigen::Infinity>() : 0.0; }

// |a - b|_inf relative to max(1e-300, |b|_inf) (b is the reference).
double rel_diff(const Vector& a, const Vector& b) {
  return inf_norm(a - b) / std::max(1e-300, inf_norm(b));
}

Matrix principal(const Matrix& M, const std::vector<Index>& idx) {
  Matrix S(idx.size(), idx.size());
  for (std::size_t a = 0; a < idx.size(); ++a)
    for (std::size_t b = 0; b < idx.size(); ++b) S(a, b) = M(idx[a], idx[b]);
  return S;
}

struct BruteForce {
  std::optional<Vector> z;  // a solution, if any basis is feasible
  int feasible_bases = 0;
  double max_spread = 0.0;  // largest |z - z_first| over feasible bases (0 for a P-matrix)
};

// Ground truth: try every one of the 2^n complementary bases, solve M_AA z_A = -q_A with a
// full-pivoting LU, and keep those with z_A >= 0 and w_F = M_FA z_A + q_F >= 0 (to a relative
// tolerance).
BruteForce brute_force(const Matrix& M, const Vector& q, double rel_tol = 1e-9) {
  const Index n = q.size();
  BruteForce out;
  const double tol = rel_tol * std::max(1e-300, inf_norm(q));
  const double ztol = tol / std::max(1.0, M.cwiseAbs().maxCoeff());  // z scales like q / M
  for (std::uint32_t mask = 0; mask < (1u << n); ++mask) {
    std::vector<Index> A;
    for (Index i = 0; i < n; ++i)
      if (mask >> i & 1u) A.push_back(i);
    Vector z = Vector::Zero(n);
    if (!A.empty()) {
      const Matrix Maa = principal(M, A);
      Eigen::FullPivLU<Matrix> lu(Maa);
      if (!lu.isInvertible()) continue;
      Vector qa(A.size());
      for (std::size_t a = 0; a < A.size(); ++a) qa[a] = q[A[a]];
      const Vector za = lu.solve(-qa);
      for (std::size_t a = 0; a < A.size(); ++a) z[A[a]] = za[a];
    }
    const Vector w = M * z + q;
    bool ok = true;
    for (Index i = 0; i < n; ++i) {
      if (mask >> i & 1u) {
        ok = ok && z[i] >= -ztol;
      } else {
        ok = ok && w[i] >= -tol;
      }
    }
    if (!ok) continue;
    ++out.feasible_bases;
    if (!out.z) {
      out.z = z.cwiseMax(0.0);
    } else {
      out.max_spread = std::max(out.max_spread, inf_norm(z.cwiseMax(0.0) - *out.z));
    }
  }
  return out;
}

// Random P-matrices of several families.
enum class Family { SymmetricPD, NearIdentity, DiagDominant, PermutedTriangular };
constexpr Family kFamilies[] = {Family::SymmetricPD, Family::NearIdentity, Family::DiagDominant,
                                Family::PermutedTriangular};

Matrix random_matrix(std::mt19937& rng, Index rows, Index cols, double lo = -1.0, double hi = 1.0) {
  std::uniform_real_distribution<double> U(lo, hi);
  Matrix A(rows, cols);
  for (Index j = 0; j < cols; ++j)
    for (Index i = 0; i < rows; ++i) A(i, j) = U(rng);
  return A;
}

Matrix random_p_matrix(std::mt19937& rng, Index n, Family family) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  switch (family) {
    case Family::SymmetricPD: {  // A A^T + delta I
      const Matrix A = random_matrix(rng, n, n);
      return A * A.transpose() + (0.2 + U(rng)) * Matrix::Identity(n, n);
    }
    case Family::NearIdentity: {  // I + E with ||E||_2 < 1: positive-definite symmetric part
      const Matrix E = random_matrix(rng, n, n);
      const double norm2 = Eigen::JacobiSVD<Matrix>(E).singularValues()(0);
      return Matrix::Identity(n, n) + (0.3 + 0.6 * U(rng)) / norm2 * E;
    }
    case Family::DiagDominant: {  // nonsymmetric, strictly row diagonally dominant
      Matrix A = random_matrix(rng, n, n);
      for (Index i = 0; i < n; ++i)
        A(i, i) = A.row(i).cwiseAbs().sum() - std::abs(A(i, i)) + 0.1 + U(rng);
      return A;
    }
    case Family::PermutedTriangular: {  // P T P^T, T upper triangular with positive diagonal:
      // every principal minor is a product of diagonal entries, but the symmetric part is in
      // general indefinite, so this is a P-matrix that is neither PD nor dominant.
      Matrix T = Matrix::Zero(n, n);
      for (Index i = 0; i < n; ++i) {
        T(i, i) = 1.0 + U(rng);
        for (Index j = i + 1; j < n; ++j) T(i, j) = 2.0 * U(rng) - 1.0;
      }
      std::vector<Index> p(n);
      for (Index i = 0; i < n; ++i) p[i] = i;
      std::shuffle(p.begin(), p.end(), rng);
      Matrix M(n, n);
      for (Index i = 0; i < n; ++i)
        for (Index j = 0; j < n; ++j) M(i, j) = T(p[i], p[j]);
      return M;
    }
  }
  return {};
}

struct Solved {
  Vector z, w;
  int pivots = 0;
};

Solved run(pwl::LcpSolver& solver, const Vector& q, const Vector& z_start) {
  Solved s;
  s.z = z_start;
  s.w = Vector::Zero(q.size());
  s.pivots = solver.solve(q, s.z, s.w).pivots;
  return s;
}

Solved run(pwl::LcpSolver& solver, const Vector& q) { return run(solver, q, Vector::Zero(q.size())); }

// Residual of the LCP relative to the sizes that enter w = M z + q.
double scaled_residual(const Matrix& M, const Vector& q, const Solved& s) {
  const double scale = std::max(inf_norm(q), (M.cwiseAbs() * s.z.cwiseAbs()).maxCoeff());
  return pwl::lcp_residual(M, q, s.z, s.w) / std::max(1e-300, scale);
}

void check_against_brute_force(const Matrix& M, const Vector& q, std::mt19937& rng) {
  const BruteForce bf = brute_force(M, q);
  REQUIRE(bf.z.has_value());
  REQUIRE(bf.max_spread <= 1e-9 * inf_norm(*bf.z));  // unique for P-matrices
  const Vector& zt = *bf.z;
  const Vector wt = (M * zt + q).cwiseMax(0.0);
  const double ztol = 1e-10 * std::max(1e-300, inf_norm(zt));
  const double wtol = 1e-10 * std::max(inf_norm(q), inf_norm(wt));

  auto lemke = pwl::make_lemke_solver();
  auto block = pwl::make_block_pivoting_solver();
  lemke->set_matrix(M);
  block->set_matrix(M);
  const Solved sl = run(*lemke, q);
  const Solved sb = run(*block, q);
  // Warm start from a random guess of the active set: must not change the answer.
  Vector guess(q.size());
  std::bernoulli_distribution coin(0.5);
  for (Index i = 0; i < q.size(); ++i) guess[i] = coin(rng) ? 1.0 : 0.0;
  const Solved sg = run(*block, q, guess);

  for (const Solved* s : {&sl, &sb, &sg}) {
    CHECK(inf_norm(s->z - zt) <= ztol + 1e-300);
    CHECK(inf_norm(s->w - wt) <= wtol);
    CHECK(scaled_residual(M, q, *s) <= 1e-11);
  }
  CHECK(inf_norm(sl.z - sb.z) <= ztol + 1e-300);
}

// The near-identity matrices of the precise-integration step: I + eps B.
Matrix near_identity(std::mt19937& rng, Index n, double eps, bool laplacian) {
  Matrix B(n, n);
  if (laplacian) {
    B.setZero();
    for (Index i = 0; i < n; ++i) {
      B(i, i) = 2.0;
      if (i + 1 < n) B(i, i + 1) = B(i + 1, i) = -1.0;
    }
  } else {
    const Matrix C = random_matrix(rng, n, n);
    B = C * C.transpose() / static_cast<double>(n);
  }
  return Matrix::Identity(n, n) + eps * B;
}

// A pure block principal pivoting method (every infeasible index switched every time, no
// fall-back), to show which problems need the fall-back. Returns false when it revisits an
// active set, i.e. cycles.
bool pure_block_pivoting_terminates(const Matrix& M, const Vector& q) {
  const Index n = q.size();
  std::set<std::uint32_t> seen;
  std::uint32_t mask = 0;
  for (;;) {
    if (!seen.insert(mask).second) return false;
    std::vector<Index> A;
    for (Index i = 0; i < n; ++i)
      if (mask >> i & 1u) A.push_back(i);
    Vector z = Vector::Zero(n);
    if (!A.empty()) {
      Vector qa(A.size());
      for (std::size_t a = 0; a < A.size(); ++a) qa[a] = q[A[a]];
      const Vector za = principal(M, A).fullPivLu().solve(-qa);
      for (std::size_t a = 0; a < A.size(); ++a) z[A[a]] = za[a];
    }
    const Vector w = M * z + q;
    std::uint32_t infeasible = 0;
    for (Index i = 0; i < n; ++i)
      if (((mask >> i & 1u) ? z[i] : w[i]) < -1e-12) infeasible |= 1u << i;
    if (!infeasible) return true;
    mask ^= infeasible;
  }
}

}  // namespace

TEST_CASE("both LCP solvers match brute-force enumeration on random P-matrix LCPs", "[lcp]") {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::uniform_int_distribution<int> decade(-4, 4);
  for (Index n = 1; n <= 10; ++n) {
    for (const Family family : kFamilies) {
      for (int rep = 0; rep < 10; ++rep) {
        // Scale M and q by unrelated powers of ten: the answer must be unit independent.
        const double mscale = std::pow(10.0, decade(rng) / 2);
        const double qscale = std::pow(10.0, decade(rng));
        const Matrix M = mscale * random_p_matrix(rng, n, family);
        Vector q(n);
        for (Index i = 0; i < n; ++i) q[i] = qscale * U(rng);
        INFO("n = " << n << ", family " << static_cast<int>(family) << ", rep " << rep);
        std::string why;
        REQUIRE(pwl::is_p_matrix(M, &why));
        check_against_brute_force(M, q, rng);
      }
    }
  }
}

TEST_CASE("LCP solvers match brute force across the cached/uncached size boundary", "[lcp]") {
  // Block pivoting caches per-active-set transforms up to n = 12 and factors directly above.
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (Index n = 11; n <= 13; ++n) {
    for (const Family family : kFamilies) {
      const Matrix M = random_p_matrix(rng, n, family);
      Vector q(n);
      for (Index i = 0; i < n; ++i) q[i] = U(rng);
      INFO("n = " << n << ", family " << static_cast<int>(family));
      check_against_brute_force(M, q, rng);
    }
  }
}

TEST_CASE("warm-started block pivoting tracks slowly varying q on near-identity matrices",
          "[lcp]") {
  struct Case {
    Index n;
    double eps;
    bool laplacian;
    int steps;
  };
  const Case cases[] = {{5, 1e-2, false, 2000}, {5, 1e-4, true, 2000}, {50, 1e-3, false, 600},
                        {50, 1e-2, true, 600},  {100, 1e-4, false, 600}, {100, 1e-2, true, 600}};
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (const Case& c : cases) {
    INFO("n = " << c.n << ", eps = " << c.eps << (c.laplacian ? ", Laplacian" : ", random PSD"));
    const Matrix M = near_identity(rng, c.n, c.eps, c.laplacian);
    Vector omega(c.n), phase(c.n);
    for (Index i = 0; i < c.n; ++i) {
      omega[i] = 0.5 + 1.5 * U(rng);
      phase[i] = 6.283185307179586 * U(rng);
    }
    // Each component changes sign a few times over the run; consecutive q are close.
    const double t_end = 8.0;
    auto q_at = [&](double t) {
      Vector q(c.n);
      for (Index i = 0; i < c.n; ++i)
        q[i] = std::sin(omega[i] * t + phase[i]) + 0.3 * std::cos(2.3 * omega[i] * t) - 0.1;
      return q;
    };
    auto warm = pwl::make_block_pivoting_solver();
    auto cold = pwl::make_block_pivoting_solver();
    auto lemke = pwl::make_lemke_solver();
    warm->set_matrix(M);
    cold->set_matrix(M);
    lemke->set_matrix(M);
    Vector z = Vector::Zero(c.n), w = Vector::Zero(c.n);
    std::vector<int> warm_pivots;
    long cold_pivot_sum = 0;
    long support_flips = 0;  // components whose state changed from one step to the next
    double active_fraction = 0.0;
    // Lemke is O(n^3) per solve: compare it on every step for small n, on a subset otherwise.
    const int lemke_every = c.n <= 5 ? 1 : 15;
    bool all_ok = true;
    for (int k = 0; k < c.steps; ++k) {
      const Vector q = q_at(t_end * k / c.steps);
      const Eigen::Array<bool, Eigen::Dynamic, 1> before = z.array() > 0.0;
      warm_pivots.push_back(warm->solve(q, z, w).pivots);  // z holds the previous solution
      if (k > 0) support_flips += ((z.array() > 0.0) != before).count();
      active_fraction += static_cast<double>((z.array() > 0.0).count()) / c.n;
      const Solved sc = run(*cold, q);
      cold_pivot_sum += sc.pivots;
      const double tol = 1e-10 * std::max(1.0, inf_norm(sc.z));
      const Solved sw{z, w, 0};
      bool ok = inf_norm(z - sc.z) <= tol && inf_norm(w - sc.w) <= 1e-10 &&
                scaled_residual(M, q, sw) <= 1e-12;
      if (k % lemke_every == 0) {
        const Solved sl = run(*lemke, q);
        ok = ok && inf_norm(z - sl.z) <= tol && scaled_residual(M, q, sl) <= 1e-11;
      }
      if (!ok) {
        all_ok = false;
        INFO("step " << k);
        CHECK(inf_norm(z - sc.z) <= tol);
        CHECK(scaled_residual(M, q, sw) <= 1e-12);
        break;
      }
    }
    CHECK(all_ok);
    // The sequence must be non-trivial: the active set keeps changing and is mixed.
    active_fraction /= c.steps;
    CHECK(support_flips >= 2 * c.n);
    CHECK(active_fraction > 0.2);
    CHECK(active_fraction < 0.8);
    std::vector<int> sorted = warm_pivots;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const int median = sorted[sorted.size() / 2];
    long warm_sum = 0;
    for (int p : warm_pivots) warm_sum += p;
    CHECK(median <= 1);
    CHECK(warm_sum < cold_pivot_sum / 4);
  }
}

TEST_CASE("warm start from any guess gives the cold-start answer", "[lcp]") {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (Index n : {3, 8, 12, 20, 40}) {
    const Matrix M = random_p_matrix(rng, n, Family::DiagDominant);
    Vector q(n);
    for (Index i = 0; i < n; ++i) q[i] = U(rng);
    auto block = pwl::make_block_pivoting_solver();
    auto lemke = pwl::make_lemke_solver();
    block->set_matrix(M);
    lemke->set_matrix(M);
    const Solved ref = run(*lemke, q);
    for (const Vector& guess : {Vector(Vector::Ones(n)), Vector(Vector::Zero(n)),
                                Vector((random_matrix(rng, n, 1).array() > 0.0).cast<double>())}) {
      const Solved s = run(*block, q, guess);
      CHECK(rel_diff(s.z, ref.z) <= 1e-10);
      CHECK(scaled_residual(M, q, s) <= 1e-12);
    }
  }
}

TEST_CASE("block pivoting needs and uses Murty's fall-back on a cycling problem", "[lcp]") {
  // A 3x3 P-matrix (minors 4, 4, 4, 46, 1, 10, 40) on which switching every infeasible index
  // at once cycles from the empty active set.
  Matrix M(3, 3);
  M << 4, -6, 3, 5, 4, -1, 5, -6, 4;
  const Vector q = (Vector(3) << 1, -3, 2).finished();
  REQUIRE(pwl::is_p_matrix(M));
  REQUIRE_FALSE(pure_block_pivoting_terminates(M, q));
  std::mt19937 rng(5);
  check_against_brute_force(M, q, rng);
  // The same with the matrix embedded in a larger, otherwise decoupled problem (n = 13 takes
  // the uncached path).
  Matrix big = Matrix::Identity(13, 13);
  big.topLeftCorner(3, 3) = M;
  Vector qbig = -Vector::Ones(13);
  qbig.head(3) = q;
  REQUIRE_FALSE(pure_block_pivoting_terminates(big, qbig));
  auto block = pwl::make_block_pivoting_solver();
  block->set_matrix(big);
  const Solved s = run(*block, qbig);
  const BruteForce bf = brute_force(M, q);
  REQUIRE(bf.z);
  CHECK(inf_norm(s.z.head(3) - *bf.z) <= 1e-12);
  CHECK(inf_norm(s.z.tail(10) - Vector::Ones(10)) <= 1e-12);
}

TEST_CASE("set_matrix invalidates what block pivoting cached for the previous matrix", "[lcp]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (Index n : {4, 13}) {
    auto block = pwl::make_block_pivoting_solver();
    const Matrix M1 = random_p_matrix(rng, n, Family::SymmetricPD);
    const Matrix M2 = random_p_matrix(rng, n, Family::DiagDominant);
    Vector q(n);
    for (Index i = 0; i < n; ++i) q[i] = U(rng);
    block->set_matrix(M1);
    const Solved s1 = run(*block, q);
    block->set_matrix(M2);
    // Same q and the same active set as a warm start: a stale cache would return M1's answer.
    const Solved s2 = run(*block, q, s1.z);
    auto lemke = pwl::make_lemke_solver();
    lemke->set_matrix(M2);
    const Solved ref = run(*lemke, q);
    REQUIRE(rel_diff(s1.z, ref.z) > 1e-6);  // the two matrices really give different answers
    CHECK(rel_diff(s2.z, ref.z) <= 1e-10);
    CHECK(scaled_residual(M2, q, s2) <= 1e-12);
  }
}

TEST_CASE("Lemke resolves degenerate problems lexicographically and terminates", "[lcp]") {
  auto lemke = pwl::make_lemke_solver();
  auto block = pwl::make_block_pivoting_solver();

  SECTION("all-tied q on I + ones: every ratio test ties") {
    for (Index n : {2, 4, 7}) {
      const Matrix M = Matrix::Identity(n, n) + Matrix::Ones(n, n);
      const Vector q = -Vector::Ones(n);
      // w = 0: z_i + sum z = 1 for all i, so z = 1 / (n + 1).
      const Vector exact = Vector::Constant(n, 1.0 / static_cast<double>(n + 1));
      for (pwl::LcpSolver* s : {lemke.get(), block.get()}) {
        s->set_matrix(M);
        const Solved r = run(*s, q);
        INFO(s->name() << ", n = " << n);
        CHECK(inf_norm(r.z - exact) <= 1e-14);
        CHECK(inf_norm(r.w) <= 1e-14);
      }
    }
  }

  SECTION("cyclic matrix with all-tied q") {
    Matrix M(3, 3);
    M << 1, 2, 0, 0, 1, 2, 2, 0, 1;
    const Vector q = -Vector::Ones(3);
    for (pwl::LcpSolver* s : {lemke.get(), block.get()}) {
      s->set_matrix(M);
      const Solved r = run(*s, q);
      CHECK(inf_norm(r.z - Vector::Constant(3, 1.0 / 3.0)) <= 1e-14);
    }
  }

  SECTION("P-matrices on which Lemke cycles without the lexicographic rule") {
    // Found by an exact-arithmetic search: with ties broken by the first (or the last) tied
    // row, Lemke's method returns to an earlier basis on these problems and never terminates.
    Matrix M4(4, 4);
    M4 << 3, -1, -1, 3, 1, 2, 0, 0, 3, 0, 1, -2, -1, -1, 2, 2;  // cycles under both rules
    Matrix M5(5, 5);
    M5 << 2, 1, 0, 1, 1, 1, 3, 1, 0, 0, 0, -1, 1, -3, 2, -3, -2, 2, 1, -1, 0, 2, -2, 3, 1;
    const Vector q4 = -Vector::Ones(4);
    const Vector q5 = (Vector(5) << 0, 0, -1, -1, -1).finished();  // cycles under last-row ties
    std::mt19937 rng(1);
    for (const auto& [M, q] : {std::pair{M4, q4}, std::pair{M5, q5}}) {
      REQUIRE(pwl::is_p_matrix(M));
      lemke->set_matrix(M);
      const Solved r = run(*lemke, q);
      CHECK(r.pivots <= 2 * (M.rows() + 1));
      check_against_brute_force(M, q, rng);
    }
  }

  SECTION("repeated rows (PSD, not P): Lemke still finds a solution") {
    // All-ones M: w_i = sum(z) - 1 for every i; the solutions are z >= 0 with sum(z) = 1.
    lemke->set_matrix(Matrix::Ones(4, 4));
    const Solved r = run(*lemke, -Vector::Ones(4));
    CHECK(pwl::lcp_residual(Matrix::Ones(4, 4), -Vector::Ones(4), r.z, r.w) <= 1e-14);
    CHECK(std::abs(r.z.sum() - 1.0) <= 1e-14);

    // Two equal rows, a zero in q and ties.
    Matrix M(4, 4);
    M << 1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 2, 1, 0, 0, 1, 2;
    const Vector q = (Vector(4) << -1, -1, 0, -3).finished();
    lemke->set_matrix(M);
    const Solved r2 = run(*lemke, q);
    CHECK(pwl::lcp_residual(M, q, r2.z, r2.w) <= 1e-14);
    CHECK(std::abs(r2.z[0] + r2.z[1] - 1.0) <= 1e-14);
    CHECK(std::abs(r2.z[2]) <= 1e-14);  // the unique solution of the decoupled (2,1;1,2) block
    CHECK(std::abs(r2.z[3] - 1.5) <= 1e-14);
  }

  SECTION("q with zeros and ties on random P-matrices, against brute force") {
    std::mt19937 rng(8);
    const std::vector<std::vector<double>> qs = {
        {0, -1, 0, -1, 0, 0.5}, {-1, -1, -1, 0, 0, 0}, {0, 0, 0, 0, 0, -1}, {-2, 0, -2, 0, -2, 0}};
    for (const Family family : kFamilies) {
      const Matrix M = random_p_matrix(rng, 6, family);
      for (const auto& qv : qs) {
        const Vector q = Eigen::Map<const Vector>(qv.data(), 6);
        check_against_brute_force(M, q, rng);
      }
    }
  }
}

TEST_CASE("components of q far below |q|_inf are resolved, not rounded away", "[lcp]") {
  // The feasibility tolerance is relative to |q|_inf; entries 1e-9 below it are still genuine.
  const Index n = 8;
  const Vector q = (Vector(n) << -1, -1e-9, 1e-9, -3e-8, 2e-10, -1e-10, 0.5, -1e-7).finished();
  std::mt19937 rng(11);
  const Matrix D = Vector::LinSpaced(n, 1.0, 2.0).asDiagonal();
  const Vector exact = (-q).cwiseMax(0.0).cwiseQuotient(D.diagonal());  // decoupled: z_i = q_i^- / d_i
  const Matrix coupled = near_identity(rng, n, 1e-3, true);
  const BruteForce bf = brute_force(coupled, q, 1e-14);
  REQUIRE(bf.z);
  REQUIRE(bf.feasible_bases == 1);
  for (auto& s : {pwl::make_lemke_solver(), pwl::make_block_pivoting_solver()}) {
    INFO(s->name());
    s->set_matrix(D);
    const Solved r = run(*s, q);
    CHECK(inf_norm(r.z - exact) <= 1e-16);
    s->set_matrix(coupled);
    const Solved rc = run(*s, q);
    CHECK(scaled_residual(coupled, q, rc) <= 1e-13);
    CHECK(inf_norm(rc.z - *bf.z) <= 1e-15);
  }
}

TEST_CASE("trivial q >= 0 needs no pivots", "[lcp]") {
  const Matrix M = (Matrix(2, 2) << 2, 1, 1, 2).finished();
  const Vector q = (Vector(2) << 0.0, 3.0).finished();
  for (auto& s : {pwl::make_lemke_solver(), pwl::make_block_pivoting_solver()}) {
    s->set_matrix(M);
    const Solved r = run(*s, q, Vector::Ones(2));  // a warm start that is wrong
    CHECK(r.pivots == 0);
    CHECK(r.z == Vector::Zero(2));
    CHECK(r.w == q);
    // The empty problem.
    s->set_matrix(Matrix(0, 0));
    Vector z0(0), w0(0);
    CHECK(s->solve(Vector(0), z0, w0).pivots == 0);
  }
}

TEST_CASE("LCPs without a solution raise LcpError instead of looping", "[lcp]") {
  struct Case {
    Matrix M;
    Vector q;
  };
  std::vector<Case> cases;
  cases.push_back({(Matrix(1, 1) << -1).finished(), (Vector(1) << -1).finished()});
  // w1 = z2 - 1, w2 = -z1 - 1 < 0 always.
  cases.push_back({(Matrix(2, 2) << 0, 1, -1, 0).finished(), (Vector(2) << -1, -1).finished()});
  cases.push_back({-Matrix::Identity(5, 5), -Vector::Ones(5)});
  // w = -z - 1 + small coupling: infeasible, size above the cache limit.
  cases.push_back({-Matrix::Identity(15, 15) - 0.01 * Matrix::Ones(15, 15), -Vector::Ones(15)});
  for (std::size_t c = 0; c < cases.size(); ++c) {
    INFO("case " << c);
    if (cases[c].M.rows() <= 10) REQUIRE_FALSE(brute_force(cases[c].M, cases[c].q).z.has_value());
    auto lemke = pwl::make_lemke_solver();
    auto block = pwl::make_block_pivoting_solver();
    lemke->set_matrix(cases[c].M);
    block->set_matrix(cases[c].M);
    Vector z = Vector::Zero(cases[c].q.size()), w = z;
    CHECK_THROWS_AS(lemke->solve(cases[c].q, z, w), pwl::LcpError);
    CHECK_THROWS_WITH(lemke->solve(cases[c].q, z, w), Catch::Contains("Lemke: ray termination"));
    z.setZero();
    CHECK_THROWS_AS(block->solve(cases[c].q, z, w), pwl::LcpError);
    z.setOnes();  // from another start, too
    CHECK_THROWS_AS(block->solve(cases[c].q, z, w), pwl::LcpError);
  }
  // The 15x15 case is not decided by brute force above; w = -(z + 0.01 sum z) - 1 < 0 for z >= 0.

  // After an error the solvers still work for a good problem.
  auto lemke = pwl::make_lemke_solver();
  auto block = pwl::make_block_pivoting_solver();
  for (pwl::LcpSolver* s : {lemke.get(), block.get()}) {
    s->set_matrix(-Matrix::Identity(2, 2));
    Vector z = Vector::Zero(2), w = z;
    CHECK_THROWS_AS(s->solve(-Vector::Ones(2), z, w), pwl::LcpError);
    s->set_matrix(2.0 * Matrix::Identity(2, 2));
    const Solved r = run(*s, -Vector::Ones(2));
    CHECK(inf_norm(r.z - Vector::Constant(2, 0.5)) <= 1e-15);
  }
}

TEST_CASE("is_p_matrix on known P and non-P matrices", "[lcp]") {
  std::string why;
  // Upper triangular with unit diagonal: minors 1, 1, 1. Its symmetric part is singular, so
  // only the exact test can accept it.
  CHECK(pwl::is_p_matrix((Matrix(2, 2) << 1, 2, 0, 1).finished(), &why));

  CHECK_FALSE(pwl::is_p_matrix((Matrix(2, 2) << 0, 1, 1, 0).finished(), &why));
  CHECK_THAT(why, Catch::Contains("{0}") && Catch::Contains("not positive"));

  CHECK_FALSE(pwl::is_p_matrix((Matrix(2, 2) << 1, 2, 2, 1).finished(), &why));
  CHECK_THAT(why, Catch::Contains("{0,1}") && Catch::Contains("-3"));

  CHECK_FALSE(pwl::is_p_matrix((Matrix(3, 3) << 1, 0, 0, 0, 1, 3, 0, 3, 1).finished(), &why));
  CHECK_THAT(why, Catch::Contains("{1,2}") && Catch::Contains("-8"));

  // Only the full determinant can be negative here.
  Matrix M3(3, 3);
  M3 << 1, 0, 2, 2, 1, 0, 0, 2, 1;  // 2x2 minors 1, 1, 1; det = 1 + 2*4 = 9 > 0: P
  CHECK(pwl::is_p_matrix(M3, &why));
  M3(0, 2) = -2;  // det = 1 - 2*4 = -7
  CHECK(M3.determinant() < 0);
  CHECK_FALSE(pwl::is_p_matrix(M3, &why));
  CHECK_THAT(why, Catch::Contains("{0,1,2}"));

  // Singular to working precision.
  CHECK_FALSE(pwl::is_p_matrix((Matrix(2, 2) << 1, 1, 1, 1 + 1e-15).finished(), &why));

  // The Murty cycling example is P.
  CHECK(pwl::is_p_matrix((Matrix(3, 3) << 4, -6, 3, 5, 4, -1, 5, -6, 4).finished()));

  // Larger than 12: sufficient tests.
  std::mt19937 rng(15);
  const Matrix dominant = random_p_matrix(rng, 15, Family::DiagDominant);
  CHECK(pwl::is_p_matrix(dominant, &why));
  const Matrix spd = random_p_matrix(rng, 15, Family::SymmetricPD);  // not dominant in general
  bool spd_dominant = true;
  for (Index i = 0; i < 15; ++i)
    spd_dominant = spd_dominant && spd(i, i) > spd.row(i).cwiseAbs().sum() - std::abs(spd(i, i));
  REQUIRE_FALSE(spd_dominant);  // so that the positive-definite branch is what accepts it
  CHECK(pwl::is_p_matrix(spd, &why));
  Matrix bad = dominant;
  bad(3, 3) = -1.0;  // the 1x1 minor {3} is negative
  CHECK_FALSE(pwl::is_p_matrix(bad, &why));
  CHECK_THAT(why, Catch::Contains("row 3"));

  // Random non-P: a negative 2x2 minor planted in a P-matrix.
  for (int rep = 0; rep < 20; ++rep) {
    Matrix M = random_p_matrix(rng, 6, Family::DiagDominant);
    M(1, 4) = M(4, 1) = 2.0 * std::sqrt(M(1, 1) * M(4, 4));  // minor {1,4} = -3 M11 M44
    CHECK_FALSE(pwl::is_p_matrix(M, &why));
  }

  CHECK_FALSE(pwl::is_p_matrix(Matrix::Ones(2, 3), &why));
  CHECK_THAT(why, Catch::Contains("2x3"));
}

TEST_CASE("lcp_residual measures each violated condition", "[lcp]") {
  const Matrix M = Matrix::Identity(2, 2);
  const Vector q = (Vector(2) << -1, 2).finished();
  CHECK(pwl::lcp_residual(M, q, (Vector(2) << 1, 0).finished(), (Vector(2) << 0, 2).finished()) ==
        0.0);
  // w - M z - q = (0.5, 0)
  CHECK(pwl::lcp_residual(M, q, (Vector(2) << 0.5, 0).finished(), (Vector(2) << 0, 2).finished()) ==
        Approx(0.5));
  // complementarity: z = (1, 0.25), w = (0, 2.25): z2 w2 = 0.5625
  CHECK(pwl::lcp_residual(M, q, (Vector(2) << 1, 0.25).finished(),
                          (Vector(2) << 0, 2.25).finished()) == Approx(0.5625));
  // negativity: z = (1, -3), w = (0, -1): -z = 3 is the largest; |z w| = 3 too
  CHECK(pwl::lcp_residual(M, q, (Vector(2) << 1, -3).finished(), (Vector(2) << 0, -1).finished()) ==
        Approx(3.0));
  CHECK(pwl::lcp_residual(M, q, (Vector(2) << 1, NAN).finished(), (Vector(2) << 0, 2).finished()) ==
        kInf);
  CHECK_THROWS_AS(pwl::lcp_residual(M, q, Vector::Zero(3), Vector::Zero(2)), pwl::InputError);
}

TEST_CASE("LCP solvers reject bad input with InputError", "[lcp]") {
  CHECK(pwl::make_lcp_solver("lemke")->name() == "lemke");
  CHECK(pwl::make_lcp_solver("block-pivoting")->name() == "block-pivoting");
  CHECK_THROWS_AS(pwl::make_lcp_solver("dantzig"), pwl::InputError);
  CHECK_THROWS_WITH(pwl::make_lcp_solver("dantzig"),
                    Catch::Contains("dantzig") && Catch::Contains("lemke") &&
                        Catch::Contains("block-pivoting"));

  for (const std::string name : {"lemke", "block-pivoting"}) {
    INFO(name);
    auto s = pwl::make_lcp_solver(name);
    Vector z = Vector::Zero(2), w = Vector::Zero(2);
    CHECK_THROWS_AS(s->solve(Vector::Zero(2), z, w), pwl::InputError);  // no matrix yet
    CHECK_THROWS_AS(s->set_matrix(Matrix::Ones(2, 3)), pwl::InputError);
    CHECK_THROWS_WITH(s->set_matrix(Matrix::Ones(2, 3)), Catch::Contains("2x3"));
    Matrix nan_m = Matrix::Identity(2, 2);
    nan_m(1, 0) = NAN;
    CHECK_THROWS_AS(s->set_matrix(nan_m), pwl::InputError);
    CHECK_THROWS_WITH(s->set_matrix(nan_m), Catch::Contains("M(1,0)") && Catch::Contains("nan"));
    nan_m(1, 0) = kInf;
    CHECK_THROWS_AS(s->set_matrix(nan_m), pwl::InputError);

    s->set_matrix(Matrix::Identity(2, 2));
    CHECK_THROWS_AS(s->solve(Vector::Zero(3), z, w), pwl::InputError);
    CHECK_THROWS_WITH(s->solve(Vector::Zero(3), z, w), Catch::Contains("q has size 3"));
    CHECK_THROWS_WITH(s->solve((Vector(2) << -1, NAN).finished(), z, w),
                      Catch::Contains("q[1]") && Catch::Contains("nan"));
    CHECK_THROWS_AS(s->solve((Vector(2) << -1, kInf).finished(), z, w), pwl::InputError);
    Vector z3 = Vector::Zero(3);
    CHECK_THROWS_AS(s->solve(Vector::Zero(2), z3, w), pwl::InputError);
    CHECK_THROWS_AS(s->solve(Vector::Zero(2), z, z3), pwl::InputError);
    // Still usable afterwards.
    const Vector q = (Vector(2) << -1, 1).finished();
    s->solve(q, z, w);
    CHECK(z == (Vector(2) << 1, 0).finished());
    CHECK(w == (Vector(2) << 0, 1).finished());
  }
}

#include "pwl/numerics/block_pivoting.hpp"

namespace {

// The pivoting rule of block_pivoting.hpp with the plainest principal solve (an Eigen LU of M_AA
// each iteration): every form built on it must pivot as the dense solver does.
struct PlainPolicy : pwl::block_pivoting::MaskedActiveSet {
  const Matrix& M;
  const Vector& q;
  pwl::block_pivoting::Tolerances tol;
  Vector x;

  PlainPolicy(const Matrix& m, const Vector& rhs, const pwl::block_pivoting::Tolerances& t)
      : M(m), q(rhs), tol(t), x(rhs.size()) {}
  int evaluate(long) {
    const int n = static_cast<int>(q.size());
    Matrix T;
    REQUIRE(pwl::block_pivoting::active_set_transform(M, n, mask, T));
    x = T * q;
    return mark_infeasible(x, n, tol);
  }
  pwl::LcpError iteration_error(long iteration) const {
    return pwl::LcpError("no solution after " + std::to_string(iteration) + " iterations");
  }
};

}  // namespace

TEST_CASE("the block pivoting core with any principal solve matches the dense solver", "[lcp]") {
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (Index n = 1; n <= 8; ++n) {
    for (const Family family : kFamilies) {
      for (int rep = 0; rep < 5; ++rep) {
        const Matrix M = random_p_matrix(rng, n, family);
        Vector q(n);
        for (Index i = 0; i < n; ++i) q[i] = U(rng);
        INFO("n = " << n << ", family " << static_cast<int>(family) << ", rep " << rep);
        auto dense = pwl::make_block_pivoting_solver();
        dense->set_matrix(M);
        const Solved expected = run(*dense, q);
        const pwl::block_pivoting::Tolerances tol =
            pwl::block_pivoting::tolerances(inf_norm(q), M.cwiseAbs().maxCoeff());
        Vector z = Vector::Zero(n), w = Vector::Zero(n);
        int pivots = 0;
        if (!pwl::block_pivoting::zero_solves(q.minCoeff(), tol)) {
          PlainPolicy policy(M, q, tol);
          pivots = pwl::block_pivoting::solve(policy, static_cast<int>(n), 100000);
          pwl::block_pivoting::split_basic_vector(
              policy.x, n, [&](Index i) { return (policy.mask >> i & 1u) != 0; }, z, w);
        } else {
          w = q.cwiseMax(0.0);
        }
        CHECK(pivots == expected.pivots);
        CHECK(inf_norm(z - expected.z) <= 1e-9 * std::max(1.0, inf_norm(expected.z)));
        CHECK(inf_norm(w - expected.w) <= 1e-9 * std::max(1.0, inf_norm(q)));
      }
    }
  }
  // A singular principal block is reported, not used.
  Matrix S = Matrix::Identity(3, 3);
  S(1, 1) = 0.0;
  Matrix T;
  CHECK_FALSE(pwl::block_pivoting::active_set_transform(S, 3, 0b010u, T));
  CHECK(pwl::block_pivoting::active_set_transform(S, 3, 0b101u, T));
}
