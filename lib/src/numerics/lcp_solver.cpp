// LCP solvers: find z with w = M z + q, z >= 0, w >= 0, z^T w = 0.
//
// References
//   C. E. Lemke, "Bimatrix equilibrium points and mathematical programming", Management Science
//     11 (1965) 681-689: complementary pivoting with an artificial variable z0.
//   R. W. Cottle, J.-S. Pang, R. E. Stone, The Linear Complementarity Problem, Academic Press
//     1992: Lemke's scheme 1 with covering vector (§4.4), lexicographic degeneracy resolution
//     (§4.9), P-matrices (§3.3).
//   J. J. Júdice, F. M. Pires 1994 and K. G. Murty 1974: block principal pivoting with Murty's
//     fall-back, whose pivoting rule is block_pivoting.hpp (cited there); this file gives it the
//     principal solves of a dense M.
//
// Both solvers are called once per integration step (~10^7 times per run) with the same M and a
// slowly changing q, so all storage is sized in set_matrix and solve() does not allocate.
#include "pwl/numerics/lcp_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "pwl/errors.hpp"
#include "pwl/numerics/block_pivoting.hpp"

namespace pwl {
namespace {

// The feasibility tolerance of block_pivoting.hpp, relative to |q|_inf; Lemke's ties use it too.
constexpr double kFeasTol = block_pivoting::kFeasibilityTolerance;
// A pivot of an LU factorisation of magnitude <= kSingularTol * k * max|entry| means singular.
constexpr double kSingularTol = 1e-13;
// Lemke: entries of the entering column <= kPivotTol * max(1, column max) do not block.
constexpr double kPivotTol = 1e-12;
// is_p_matrix: a principal minor must exceed this fraction of the product of its rows' 2-norms
// (Hadamard's bound on |det|), otherwise it is zero to working precision.
constexpr double kMinorTol = 1e-12;
constexpr int kBlockTries = block_pivoting::kBlockTries;
// Active sets up to this size are encoded as bitmasks and their transforms cached.
constexpr Index kMaxCachedSize = 12;

// ---------------------------------------------------------------------------------------------
// Dense LU with partial pivoting on a row-major k x k array, in place (P a = L U, P stored as
// LAPACK-style row transpositions). Hand-written so that it runs in caller-owned storage: an
// Eigen decomposition object would allocate its permutation on every construction.
// Returns the first column whose pivot magnitude is <= tiny (the factorisation stops there), or
// -1. *sign receives the determinant sign of P.
int lu_factor(double* a, int k, int* perm, double tiny, int* sign = nullptr) {
  int s = 1;
  for (int j = 0; j < k; ++j) {
    int p = j;
    double best = std::abs(a[j * k + j]);
    for (int i = j + 1; i < k; ++i) {
      const double v = std::abs(a[i * k + j]);
      if (v > best) {
        best = v;
        p = i;
      }
    }
    perm[j] = p;
    if (p != j) {
      std::swap_ranges(a + j * k, a + j * k + k, a + p * k);
      s = -s;
    }
    if (sign) *sign = s;
    if (!(best > tiny)) return j;
    const double inv = 1.0 / a[j * k + j];
    for (int i = j + 1; i < k; ++i) {
      const double l = (a[i * k + j] *= inv);
      if (l == 0.0) continue;
      for (int c = j + 1; c < k; ++c) a[i * k + c] -= l * a[j * k + c];
    }
  }
  if (sign) *sign = s;
  return -1;
}

// Solves (L U) x = P b in place in b, after lu_factor returned -1.
void lu_solve(const double* a, int k, const int* perm, double* b) {
  for (int j = 0; j < k; ++j)
    if (perm[j] != j) std::swap(b[j], b[perm[j]]);
  for (int i = 1; i < k; ++i) {
    double s = b[i];
    for (int c = 0; c < i; ++c) s -= a[i * k + c] * b[c];
    b[i] = s;
  }
  for (int i = k - 1; i >= 0; --i) {
    double s = b[i];
    for (int c = i + 1; c < k; ++c) s -= a[i * k + c] * b[c];
    b[i] = s / a[i * k + i];
  }
}

std::string format_index_set(const int* idx, int k) {
  std::string s = "{";
  for (int a = 0; a < k; ++a) {
    if (a) s += ',';
    s += std::to_string(idx[a]);
  }
  s += '}';
  return s;
}

std::string format_mask(std::uint32_t mask) {
  int idx[32];
  int k = 0;
  for (int i = 0; i < 32; ++i)
    if (mask >> i & 1u) idx[k++] = i;
  return format_index_set(idx, k);
}

// ---------------------------------------------------------------------------------------------
// Input validation shared by both solvers.

// Throws InputError unless M is square and finite. Returns max |M_ij|.
double validate_matrix(const Matrix& M, const char* who) {
  if (M.rows() != M.cols())
    throw InputError(fmt::format("{}: set_matrix: M is {}x{}; it must be square", who, M.rows(),
                                 M.cols()));
  double mmax = 0.0;
  for (Index j = 0; j < M.cols(); ++j)
    for (Index i = 0; i < M.rows(); ++i) {
      const double v = M(i, j);
      if (!std::isfinite(v))
        throw InputError(fmt::format("{}: set_matrix: M({},{}) = {} is not finite", who, i, j, v));
      mmax = std::max(mmax, std::abs(v));
    }
  return mmax;
}

struct RhsInfo {
  double qmax = 0.0;  // |q|_inf
  double qmin = 0.0;  // min_i q_i (0 for n = 0)
};

// Throws InputError unless q, z and w have the size of M and q is finite.
RhsInfo validate_solve(const char* who, bool has_matrix, Index n,
                       const Eigen::Ref<const Vector>& q, const Eigen::Ref<Vector>& z,
                       const Eigen::Ref<Vector>& w) {
  if (!has_matrix) throw InputError(fmt::format("{}: solve called before set_matrix", who));
  if (q.size() != n)
    throw InputError(fmt::format("{}: solve: q has size {}, expected {} (the size of M)", who,
                                 q.size(), n));
  if (z.size() != n)
    throw InputError(fmt::format("{}: solve: z has size {}, expected {} (the size of M)", who,
                                 z.size(), n));
  if (w.size() != n)
    throw InputError(fmt::format("{}: solve: w has size {}, expected {} (the size of M)", who,
                                 w.size(), n));
  RhsInfo info;
  info.qmin = n > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  for (Index i = 0; i < n; ++i) {
    const double v = q[i];
    if (!std::isfinite(v))
      throw InputError(fmt::format("{}: solve: q[{}] = {} is not finite", who, i, v));
    info.qmax = std::max(info.qmax, std::abs(v));
    info.qmin = std::min(info.qmin, v);
  }
  return info;
}

// ---------------------------------------------------------------------------------------------
// Lemke's method (scheme 1 of Cottle, Pang & Stone §4.4) on the tableau
//
//     [ I | -M/s | -e | q/s ]      columns: w_0..w_{n-1}, z_0..z_{n-1}, z0, right-hand side,
//
// where s = max|M_ij| makes the z columns O(1), so that absolute pivot thresholds make sense
// (the scaling leaves z unchanged and divides w by s). Because the w columns start as I, they
// hold the basis inverse at every step, which is what the lexicographic ratio test compares.
class LemkeSolver final : public LcpSolver {
 public:
  std::string name() const override { return "lemke"; }
  LcpAlgorithm algorithm() const override { return LcpAlgorithm::lemke; }

  void set_matrix(const Matrix& M) override {
    const double mmax = validate_matrix(M, "Lemke");
    n_ = M.rows();
    scale_ = mmax > 0.0 ? mmax : 1.0;
    Mn_ = M / scale_;
    width_ = 2 * n_ + 2;
    tab_.assign(static_cast<std::size_t>(n_ * width_), 0.0);
    basis_.assign(static_cast<std::size_t>(n_), 0);
    cand_.assign(static_cast<std::size_t>(n_), 0);
    // Lemke with lexicographic pivoting visits each almost-complementary basis at most once;
    // this cap is far above what any P-matrix problem needs and only guards against bugs and
    // numerical breakdown.
    max_pivots_ = 50 * (n_ + 1) * (n_ + 1);
    has_matrix_ = true;
  }

  LcpResult solve(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z,
                  Eigen::Ref<Vector> w) override {
    const RhsInfo info = validate_solve("Lemke", has_matrix_, n_, q, z, w);
    LcpResult result;
    const double tol_w = kFeasTol * info.qmax;
    if (info.qmin >= -tol_w) {  // z = 0 solves it
      z.setZero();
      for (Index i = 0; i < n_; ++i) w[i] = std::max(q[i], 0.0);
      return result;
    }
    const Index n = n_, W = width_, cz0 = 2 * n, crhs = 2 * n + 1;
    // Fill the tableau.
    for (Index i = 0; i < n; ++i) {
      double* row = &tab_[static_cast<std::size_t>(i * W)];
      for (Index j = 0; j < n; ++j) row[j] = (i == j) ? 1.0 : 0.0;
      for (Index j = 0; j < n; ++j) row[n + j] = -Mn_(i, j);
      row[cz0] = -1.0;
      row[crhs] = q[i] / scale_;
      basis_[static_cast<std::size_t>(i)] = static_cast<int>(i);
    }
    tie_tol_ = kFeasTol * info.qmax / scale_;

    // First pivot: z0 enters at the level that makes every w non-negative; the row of the most
    // negative q leaves. With the lexicographic perturbation q_i + eps^i, ties go to the largest
    // index.
    Index r = 0;
    {
      double best = std::numeric_limits<double>::infinity();
      for (Index i = 0; i < n; ++i) best = std::min(best, at(i, crhs));
      for (Index i = 0; i < n; ++i)
        if (at(i, crhs) <= best + tie_tol_) r = i;
    }
    Index leaving = basis_[static_cast<std::size_t>(r)];
    pivot(r, cz0);
    result.pivots = 1;

    for (;;) {
      if (leaving == cz0) break;  // z0 left the basis: the basis is complementary
      // The complement of the variable that just left enters.
      const Index entering = leaving < n ? leaving + n : leaving - n;
      r = ratio_test(entering);
      if (r < 0)
        throw LcpError(fmt::format(
            "Lemke: ray termination after {} pivots (n = {}): the LCP has no solution reachable "
            "(M is not a P-matrix?)",
            result.pivots, n));
      if (result.pivots >= max_pivots_)
        throw LcpError(fmt::format(
            "Lemke: no complementary basis after {} pivots (n = {}), the iteration limit "
            "(M is not a P-matrix, or numerical breakdown)",
            result.pivots, n));
      leaving = basis_[static_cast<std::size_t>(r)];
      pivot(r, entering);
      ++result.pivots;
    }

    // Read the basic solution off the tableau; nonbasic variables are 0.
    z.setZero();
    w.setZero();
    for (Index i = 0; i < n; ++i) {
      const Index v = basis_[static_cast<std::size_t>(i)];
      const double val = std::max(at(i, crhs), 0.0);  // clamp rounding-level negatives
      if (v < n)
        w[v] = val * scale_;
      else if (v < 2 * n)
        z[v - n] = val;
    }
    return result;
  }

 private:
  double& at(Index i, Index j) { return tab_[static_cast<std::size_t>(i * width_ + j)]; }

  // Gauss-Jordan pivot on (r, c): column c becomes the unit vector e_r.
  void pivot(Index r, Index c) {
    const Index W = width_;
    double* pr = &tab_[static_cast<std::size_t>(r * W)];
    const double inv = 1.0 / pr[c];
    for (Index j = 0; j < W; ++j) pr[j] *= inv;
    pr[c] = 1.0;
    for (Index i = 0; i < n_; ++i) {
      if (i == r) continue;
      double* pi = &tab_[static_cast<std::size_t>(i * W)];
      const double f = pi[c];
      if (f == 0.0) continue;
      for (Index j = 0; j < W; ++j) pi[j] -= f * pr[j];
      pi[c] = 0.0;
    }
    basis_[static_cast<std::size_t>(r)] = static_cast<int>(c);
  }

  // Lexicographic minimum-ratio test for entering column c: among rows with a positive entry,
  // the smallest rhs_i / a_ic; ties are broken by the rows of (basis inverse) / a_ic compared
  // lexicographically, which is the minimum ratio for the perturbed q + (eps, eps^2, ...) and
  // rules out cycling. If z0's row is among the ties it leaves at once (that ends the
  // algorithm, so it cannot cycle either). Returns -1 on a ray.
  Index ratio_test(Index c) {
    const Index n = n_, crhs = 2 * n + 1, cz0 = 2 * n;
    double colmax = 0.0;
    for (Index i = 0; i < n; ++i) colmax = std::max(colmax, std::abs(at(i, c)));
    const double thresh = kPivotTol * std::max(1.0, colmax);
    double best = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < n; ++i) {
      const double a = at(i, c);
      if (a > thresh) best = std::min(best, std::max(at(i, crhs), 0.0) / a);
    }
    if (best == std::numeric_limits<double>::infinity()) return -1;
    Index ncand = 0;
    for (Index i = 0; i < n; ++i) {
      const double a = at(i, c);
      if (a > thresh && std::max(at(i, crhs), 0.0) / a <= best + tie_tol_) {
        if (basis_[static_cast<std::size_t>(i)] == cz0) return i;
        cand_[static_cast<std::size_t>(ncand++)] = static_cast<int>(i);
      }
    }
    // Column k of the basis inverse is the tableau's w_k column.
    for (Index k = 0; k < n && ncand > 1; ++k) {
      double lo = std::numeric_limits<double>::infinity();
      for (Index t = 0; t < ncand; ++t) {
        const Index i = cand_[static_cast<std::size_t>(t)];
        lo = std::min(lo, at(i, k) / at(i, c));
      }
      Index kept = 0;
      for (Index t = 0; t < ncand; ++t) {
        const Index i = cand_[static_cast<std::size_t>(t)];
        if (at(i, k) / at(i, c) <= lo + kPivotTol) cand_[static_cast<std::size_t>(kept++)] = i;
      }
      ncand = kept;
    }
    return cand_[0];
  }

  Index n_ = 0;
  Index width_ = 0;
  double scale_ = 1.0;
  double tie_tol_ = 0.0;
  Index max_pivots_ = 0;
  bool has_matrix_ = false;
  Matrix Mn_;                // M / scale_
  std::vector<double> tab_;  // n x (2n + 2), row-major
  std::vector<int> basis_;   // basic variable of each row: w_i = i, z_i = n + i, z0 = 2n
  std::vector<int> cand_;    // rows tied in the ratio test
};

// ---------------------------------------------------------------------------------------------
// Block principal pivoting (Júdice & Pires 1994) with Murty's fall-back: the rule of
// block_pivoting.hpp with the principal solves of a dense M.
//
// For n <= 12, x = T_A q with an n x n matrix T_A that depends only on M and A; T_A is computed
// the first time A is met and cached, keyed by A's bitmask, so a warm-started step whose active
// set was seen before costs one n x n matrix-vector product.
class BlockPivotingSolver final : public LcpSolver {
 public:
  std::string name() const override { return "block-pivoting"; }
  LcpAlgorithm algorithm() const override { return LcpAlgorithm::block_pivoting; }

  void set_matrix(const Matrix& M) override {
    const double mmax = validate_matrix(M, "block pivoting");
    const Index old_n = has_matrix_ ? n_ : -1;
    n_ = M.rows();
    M_ = M;
    mscale_ = mmax > 0.0 ? mmax : 1.0;
    const auto n = static_cast<std::size_t>(n_);
    if (n_ <= kMaxCachedSize) {
      const std::size_t nsets = std::size_t{1} << n;
      if (old_n != n_) tcache_.assign(nsets * n * n, 0.0);
      tvalid_.assign(nsets, 0);  // a new M invalidates every cached transform
      static const auto table =
          small_solvers(std::make_index_sequence<static_cast<std::size_t>(kMaxCachedSize)>());
      small_solve_ = n_ > 0 ? table[n - 1] : nullptr;
      // Bound on the iterations of a P-matrix problem: at most n + 1 values of the best count,
      // each with up to kBlockTries + 1 block iterations and a Murty run that visits each of
      // the 2^n bases at most once.
      max_iter_ = std::max<long>(50L * (n_ + 1) * (n_ + 1),
                                 (n_ + 1) * (static_cast<long>(nsets) + kBlockTries + 2));
    } else {
      tcache_.clear();
      tvalid_.clear();
      max_iter_ = 50L * (n_ + 1) * (n_ + 1);
    }
    lu_.assign(n * n, 0.0);
    perm_.assign(n, 0);
    idx_a_.assign(n, 0);
    x_.assign(n, 0.0);
    y_.assign(n, 0.0);
    active_.assign(n, 0);
    fact_active_.assign(n, 0);
    fact_valid_ = false;
    has_matrix_ = true;
  }

  LcpResult solve(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z,
                  Eigen::Ref<Vector> w) override {
    const RhsInfo info = validate_solve("block pivoting", has_matrix_, n_, q, z, w);
    LcpResult result;
    const block_pivoting::Tolerances tol = block_pivoting::tolerances(info.qmax, mscale_);
    if (block_pivoting::zero_solves(info.qmin, tol)) {
      z.setZero();
      for (Index i = 0; i < n_; ++i) w[i] = std::max(q[i], 0.0);
      return result;
    }
    if (n_ <= kMaxCachedSize)
      (this->*small_solve_)(q, z, w, tol, result);
    else
      solve_large(q, z, w, tol, result);
    return result;
  }

 private:
  // Transform T_A (row-major, n x n) for the active set `mask`, computing it if needed.
  const double* transform(std::uint32_t mask, long iter) {
    const auto n = static_cast<std::size_t>(n_);
    double* T = &tcache_[mask * n * n];
    if (tvalid_[mask]) return T;
    const int ni = static_cast<int>(n_);
    int ia[kMaxCachedSize];
    int k = 0;
    for (int i = 0; i < ni; ++i)
      if (mask >> i & 1u) ia[k++] = i;
    // Factor M_AA.
    double* A = lu_.data();
    double amax = 0.0;
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) {
        A[a * k + b] = M_(ia[a], ia[b]);
        amax = std::max(amax, std::abs(A[a * k + b]));
      }
    if (lu_factor(A, k, perm_.data(), kSingularTol * k * amax) >= 0)
      throw singular_block(ia, k, iter);
    // X = M_AA^{-1}, column by column into y_ and then into the rows of T.
    std::fill(T, T + n * n, 0.0);
    double X[kMaxCachedSize * kMaxCachedSize];
    for (int b = 0; b < k; ++b) {
      double* col = y_.data();
      for (int a = 0; a < k; ++a) col[a] = (a == b) ? 1.0 : 0.0;
      lu_solve(A, k, perm_.data(), col);
      for (int a = 0; a < k; ++a) X[a * k + b] = col[a];
    }
    // Rows of A: z_A = -X q_A. Rows of F: w_F = q_F - M_FA X q_A.
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) T[ia[a] * ni + ia[b]] = -X[a * k + b];
    for (int i = 0; i < ni; ++i) {
      if (mask >> i & 1u) continue;
      double* Ti = T + i * ni;
      Ti[i] = 1.0;
      for (int b = 0; b < k; ++b) {
        double s = 0.0;
        for (int a = 0; a < k; ++a) s += M_(i, ia[a]) * X[a * k + b];
        Ti[ia[b]] = -s;
      }
    }
    tvalid_[mask] = 1;
    return T;
  }

  // The principal solves for n = N <= 12: x = T_A q with the cached transform of A. Instantiated
  // for every size 1..12: with the size known at compile time the matrix-vector product and the
  // loops unroll (about 30% fewer instructions per warm step).
  template <int N>
  struct CachedInversePolicy : block_pivoting::MaskedActiveSet {
    BlockPivotingSolver& solver;
    const double* q;
    block_pivoting::Tolerances tol;
    double x[kMaxCachedSize];

    int evaluate(long iteration) {
      const double* T = solver.transform(mask, iteration);
      for (int i = 0; i < N; ++i) {
        const double* Ti = T + i * N;
        double s = 0.0;
        for (int j = 0; j < N; ++j) s += Ti[j] * q[j];
        x[i] = s;
      }
      return mark_infeasible(x, N, tol);
    }
    LcpError iteration_error(long iteration) const { return solver.iteration_limit(iteration); }
  };

  template <int N>
  void solve_small(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z, Eigen::Ref<Vector> w,
                   const block_pivoting::Tolerances& tol, LcpResult& result) {
    CachedInversePolicy<N> policy{{}, *this, q.data(), tol, {}};
    for (int i = 0; i < N; ++i)
      if (z[i] > 0.0) policy.mask |= 1u << i;
    result.pivots += block_pivoting::solve(policy, N, max_iter_);
    block_pivoting::split_basic_vector(
        policy.x, N, [&](Index i) { return (policy.mask >> i & 1u) != 0; }, z, w);
  }

  // The principal solves for n > 12: M_AA is factored for each new active set; the
  // factorisation of the last one is kept, so a step whose active set did not change costs two
  // triangular solves and M_FA z_A.
  struct FactoredBlockPolicy {
    BlockPivotingSolver& solver;
    const Eigen::Ref<const Vector>& q;
    block_pivoting::Tolerances tol;
    Index last = -1;  // the largest infeasible index

    bool infeasible(Index i) const {
      const double t = solver.active_[static_cast<std::size_t>(i)] ? tol.z : tol.w;
      return solver.x_[static_cast<std::size_t>(i)] < -t;
    }
    int evaluate(long iteration) {
      BlockPivotingSolver& s = solver;
      const Index n = s.n_;
      int k = 0;
      for (Index i = 0; i < n; ++i)
        if (s.active_[static_cast<std::size_t>(i)]) s.idx_a_[static_cast<std::size_t>(k++)] =
            static_cast<int>(i);
      if (!s.fact_valid_ || s.active_ != s.fact_active_) {
        s.fact_valid_ = false;
        double amax = 0.0;
        for (int a = 0; a < k; ++a)
          for (int b = 0; b < k; ++b) {
            const double v = s.M_(s.idx_a_[a], s.idx_a_[b]);
            s.lu_[static_cast<std::size_t>(a * k + b)] = v;
            amax = std::max(amax, std::abs(v));
          }
        if (lu_factor(s.lu_.data(), k, s.perm_.data(), kSingularTol * k * amax) >= 0)
          throw s.singular_block(s.idx_a_.data(), k, iteration);
        s.fact_active_ = s.active_;  // same size: no allocation
        s.fact_valid_ = true;
      }
      double* x = s.x_.data();
      double* zA = s.y_.data();
      for (int a = 0; a < k; ++a) zA[a] = -q[s.idx_a_[a]];
      lu_solve(s.lu_.data(), k, s.perm_.data(), zA);
      for (Index i = 0; i < n; ++i) x[i] = q[i];
      for (int a = 0; a < k; ++a) {
        const double za = zA[a];
        const double* col = s.M_.data() + static_cast<Index>(s.idx_a_[a]) * n;
        for (Index i = 0; i < n; ++i) x[i] += col[i] * za;
      }
      for (int a = 0; a < k; ++a) x[s.idx_a_[a]] = zA[a];
      int count = 0;
      last = -1;
      for (Index i = 0; i < n; ++i) {
        if (infeasible(i)) {
          ++count;
          last = i;
        }
      }
      return count;
    }
    void exchange_infeasible() {
      for (Index i = 0; i < solver.n_; ++i)
        if (infeasible(i)) solver.active_[static_cast<std::size_t>(i)] ^= 1;
    }
    void exchange_largest_infeasible() { solver.active_[static_cast<std::size_t>(last)] ^= 1; }
    LcpError iteration_error(long iteration) const { return solver.iteration_limit(iteration); }
  };

  void solve_large(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z, Eigen::Ref<Vector> w,
                   const block_pivoting::Tolerances& tol, LcpResult& result) {
    const Index n = n_;
    for (Index i = 0; i < n; ++i) active_[static_cast<std::size_t>(i)] = z[i] > 0.0 ? 1 : 0;
    FactoredBlockPolicy policy{*this, q, tol};
    result.pivots += block_pivoting::solve(policy, static_cast<int>(n), max_iter_);
    block_pivoting::split_basic_vector(
        x_, n, [&](Index i) { return active_[static_cast<std::size_t>(i)] != 0; }, z, w);
  }

  LcpError singular_block(const int* idx, int k, long iter) const {
    return LcpError(fmt::format(
        "block pivoting: principal block M_AA for the active set A = {} (size {} of n = {}) is "
        "singular at iteration {} (M is not a P-matrix?)",
        format_index_set(idx, k), k, n_, iter));
  }

  LcpError iteration_limit(long iter) const {
    return LcpError(fmt::format(
        "block pivoting: no solution after {} iterations (n = {}), the iteration limit "
        "(M is not a P-matrix?)",
        iter, n_));
  }

  using SmallSolve = void (BlockPivotingSolver::*)(const Eigen::Ref<const Vector>&,
                                                   Eigen::Ref<Vector>, Eigen::Ref<Vector>,
                                                   const block_pivoting::Tolerances&, LcpResult&);
  template <std::size_t... I>
  static std::array<SmallSolve, sizeof...(I)> small_solvers(std::index_sequence<I...>) {
    return {&BlockPivotingSolver::solve_small<static_cast<int>(I) + 1>...};
  }

  Index n_ = 0;
  bool has_matrix_ = false;
  SmallSolve small_solve_ = nullptr;  // solve_small<n_> for 1 <= n_ <= 12
  double mscale_ = 1.0;
  long max_iter_ = 0;
  Matrix M_;
  // n <= 12: T_A for every bitmask A (n*n doubles each) and whether it has been computed.
  std::vector<double> tcache_;
  std::vector<std::uint8_t> tvalid_;
  // Workspaces.
  std::vector<double> lu_;
  std::vector<int> perm_;
  std::vector<int> idx_a_;
  std::vector<double> x_, y_;
  std::vector<std::uint8_t> active_, fact_active_;  // n > 12: current / factored active set
  bool fact_valid_ = false;
};

}  // namespace

std::unique_ptr<LcpSolver> make_lemke_solver() { return std::make_unique<LemkeSolver>(); }

std::unique_ptr<LcpSolver> make_block_pivoting_solver() {
  return std::make_unique<BlockPivotingSolver>();
}

std::string lcp_algorithm_name(LcpAlgorithm algorithm) {
  return algorithm == LcpAlgorithm::lemke ? "lemke" : "block-pivoting";
}

LcpAlgorithm parse_lcp_algorithm(const std::string& name) {
  if (name == "lemke") return LcpAlgorithm::lemke;
  if (name == "block-pivoting") return LcpAlgorithm::block_pivoting;
  throw InputError(fmt::format(
      "LCP solver name '{}' is not known; accepted names are 'lemke' and 'block-pivoting'", name));
}

std::unique_ptr<LcpSolver> make_lcp_solver(LcpAlgorithm algorithm) {
  return algorithm == LcpAlgorithm::lemke ? make_lemke_solver() : make_block_pivoting_solver();
}

std::unique_ptr<LcpSolver> make_lcp_solver(const std::string& name) {
  return make_lcp_solver(parse_lcp_algorithm(name));
}

bool is_p_matrix(const Matrix& M, std::string* why) {
  auto fail = [why](std::string msg) {
    if (why) *why = std::move(msg);
    return false;
  };
  if (M.rows() != M.cols())
    return fail(fmt::format("M is {}x{}, not square", M.rows(), M.cols()));
  if (!M.allFinite()) return fail("M has a non-finite entry");
  const Index n = M.rows();
  if (n <= kMaxCachedSize) {
    // Exact: every principal minor, smallest subsets first so that a failure names the
    // smallest offending one. The LU determinant is backward stable; a minor counts as positive
    // only if it is a non-negligible fraction of Hadamard's bound prod ||row||_2.
    const int ni = static_cast<int>(n);
    double A[kMaxCachedSize * kMaxCachedSize];
    int perm[kMaxCachedSize];
    int ia[kMaxCachedSize];
    for (int k = 1; k <= ni; ++k) {
      for (std::uint32_t mask = 1; mask < (1u << ni); ++mask) {
        if (std::popcount(mask) != k) continue;
        int m = 0;
        for (int i = 0; i < ni; ++i)
          if (mask >> i & 1u) ia[m++] = i;
        double hadamard = 1.0;
        for (int a = 0; a < k; ++a) {
          double r2 = 0.0;
          for (int b = 0; b < k; ++b) {
            const double v = M(ia[a], ia[b]);
            A[a * k + b] = v;
            r2 += v * v;
          }
          hadamard *= std::sqrt(r2);
        }
        int sign = 1;
        double det = 0.0;
        if (lu_factor(A, k, perm, 0.0, &sign) < 0) {
          det = sign;
          for (int a = 0; a < k; ++a) det *= A[a * k + a];
        }
        if (!(det > kMinorTol * hadamard)) {
          const std::string set = format_mask(mask);
          if (det > 0.0)
            return fail(fmt::format(
                "principal minor {} = {:g} is not positive to working precision (Hadamard bound "
                "{:g})",
                set, det, hadamard));
          return fail(fmt::format("principal minor {} = {:g} is not positive", set, det));
        }
      }
    }
    return true;
  }
  // Sufficient tests for larger matrices.
  // (a) Strict row diagonal dominance with a positive diagonal: every principal submatrix
  //     inherits it, so every principal minor is positive.
  std::string dominance_failure;
  for (Index i = 0; i < n && dominance_failure.empty(); ++i) {
    double off = 0.0;
    for (Index j = 0; j < n; ++j)
      if (j != i) off += std::abs(M(i, j));
    if (!(M(i, i) > off))
      dominance_failure = fmt::format("row {}: M({},{}) = {:g} <= sum of |off-diagonal| = {:g}",
                                      i, i, i, M(i, i), off);
  }
  if (dominance_failure.empty()) return true;
  // (b) Positive-definite symmetric part: x^T M x > 0 for x != 0 on every principal subspace.
  const Matrix S = 0.5 * (M + M.transpose());
  Eigen::LLT<Matrix> llt(S);
  bool pd = llt.info() == Eigen::Success;
  if (pd) {
    const auto d = llt.matrixLLT().diagonal();
    const double smax = S.diagonal().cwiseAbs().maxCoeff();
    pd = d.cwiseAbs2().minCoeff() > kMinorTol * smax;
  }
  if (pd) return true;
  return fail(fmt::format(
      "size {} > {}: the sufficient tests fail (not strictly diagonally dominant: {}; symmetric "
      "part not positive definite); M may still be a P-matrix",
      n, kMaxCachedSize, dominance_failure));
}

double lcp_residual(const Matrix& M, const Vector& q, const Vector& z, const Vector& w) {
  const Index n = q.size();
  if (M.rows() != n || M.cols() != n || z.size() != n || w.size() != n)
    throw InputError(fmt::format(
        "lcp_residual: sizes do not match: M is {}x{}, q has {}, z has {}, w has {} entries",
        M.rows(), M.cols(), n, z.size(), w.size()));
  double r = 0.0;
  for (Index i = 0; i < n; ++i) {
    const double mz = M.row(i).dot(z);
    // std::max would silently drop a NaN: report anything non-finite as an infinite violation.
    if (!std::isfinite(z[i]) || !std::isfinite(w[i]) || !std::isfinite(mz) || !std::isfinite(q[i]))
      return std::numeric_limits<double>::infinity();
    r = std::max({r, -z[i], -w[i], std::abs(w[i] - mz - q[i]), std::abs(z[i] * w[i])});
  }
  return r;
}

}  // namespace pwl
