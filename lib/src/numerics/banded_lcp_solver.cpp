// Banded LCP solver: block principal pivoting (Júdice & Pires, Computers & Operations Research
// 21 (1994) 587-596) with Murty's single principal pivoting as the fall-back (Murty, Opsearch 11
// (1974) 123-130), whose pivoting rule is block_pivoting.hpp, on active-set systems solved in
// O(size · bandwidth): Jacobi sweeps for a diagonally dominant matrix, a band LU without pivoting
// otherwise (positive pivots on a P-matrix: Cottle, Pang & Stone, The Linear Complementarity
// Problem, 1992, §3.3).
#include "pwl/numerics/banded_lcp_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/numerics/block_pivoting.hpp"

namespace pwl {
namespace {

// As in the dense solver: pivots of M_AA below kSingularTol · width · max|M| mean singular.
constexpr double kSingularTol = 1e-13;
// The sweeps stop when the error they leave, bounded from the last sweep's move, is at most this
// fraction of the largest force (a few units of rounding).
constexpr double kSweepTol = 4.0 * std::numeric_limits<double>::epsilon();

// Jacobi's error after a sweep that moved the forces by at most δ is at most δ ρ / (1 - ρ), so
// the sweeps end once that is at rounding: for ρ of the step's matrix (about 1e-7) one sweep
// fewer than waiting for a sweep that no longer moves them. Past ρ = 1/2 the bound exceeds the
// move, whose own rounding would then never pass the test: the sweeps end on a move at
// rounding, as Gauss-Seidel's did.
double error_per_move(double rho) { return std::min(1.0, rho / (1.0 - rho)); }

LcpError iteration_limit(long iteration, Index n) {
  return LcpError(fmt::format(
      "banded block pivoting: no solution after {} iterations (n = {}), the iteration limit "
      "(M is not a P-matrix?)",
      iteration, n));
}

}  // namespace

bool BandedLcpOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!(dominance_limit >= 0.0 && dominance_limit < 1.0)) {
    *why = fmt::format("dominance_limit = {} must be in [0, 1)", dominance_limit);
    return false;
  }
  if (max_sweeps < 1) {
    *why = fmt::format("max_sweeps = {} must be at least 1", max_sweeps);
    return false;
  }
  return true;
}

BandedLcpSolver::BandedLcpSolver(const BandedLcpOptions& options) : options_(options) {
  std::string why;
  if (!options_.is_valid(&why)) throw InputError("banded LCP options: " + why);
}

void BandedLcpSolver::set_matrix(const Matrix& M) {
  if (M.rows() != M.cols()) {
    throw InputError(fmt::format("banded LCP: set_matrix: M is {}x{}; it must be square",
                                 M.rows(), M.cols()));
  }
  set_matrix(BandedMatrix::from_dense_nonzeros(M));
}

void BandedLcpSolver::set_matrix(const BandedMatrix& M) {
  if (M.rows() != M.cols()) {
    throw InputError(fmt::format("banded LCP: set_matrix: M is {}x{}; it must be square",
                                 M.rows(), M.cols()));
  }
  const Index n = M.rows();
  M_ = M;
  scale_ = 0.0;
  diagonal_.resize(n);
  inverse_diagonal_.resize(n);
  dominance_ = 0.0;
  for (Index i = 0; i < n; ++i) {
    const double* a = M_.row_values(i);
    double off = 0.0;
    for (Index k = 0; k < M_.width(); ++k) {
      if (!std::isfinite(a[k])) {
        throw InputError(fmt::format("banded LCP: set_matrix: M({},{}) = {} is not finite", i,
                                     M_.first_column(i) + k, a[k]));
      }
      scale_ = std::max(scale_, std::abs(a[k]));
      if (M_.first_column(i) + k != i) off += std::abs(a[k]);
    }
    diagonal_[i] = M_.coeff(i, i);
    inverse_diagonal_[i] = 1.0 / diagonal_[i];
    dominance_ = diagonal_[i] > 0.0 ? std::max(dominance_, off / diagonal_[i])
                                    : std::numeric_limits<double>::infinity();
  }
  if (scale_ == 0.0) scale_ = 1.0;
  // Sweeps from a cold start (a first move of the size of the forces) reach rounding after
  // about log(kSweepTol / error_per_move) / log ρ of them (jacobi_sweeps); where that exceeds
  // max_sweeps they would all be spent before the factorisation, so factorise from the start.
  const double sweeps_to_rounding =
      dominance_ > 0.0 ? std::log(kSweepTol / error_per_move(dominance_)) / std::log(dominance_) + 1.0
                       : 1.0;
  iterate_ = dominance_ <= options_.dominance_limit && sweeps_to_rounding <= options_.max_sweeps;
  lower_ = M_.lower_bandwidth();
  upper_ = M_.upper_bandwidth();
  columns_ = transpose(M_);
  const auto size = static_cast<std::size_t>(n);
  lu_.assign(size * static_cast<std::size_t>(lower_ + upper_ + 1), 0.0);
  rhs_.assign(size, 0.0);
  next_.assign(size, 0.0);
  active_.assign(size, 0);
  set_.clear();
  set_.reserve(size);
  factored_.clear();
  factored_.reserve(size);
  x_.setZero(n);
  // As in the dense solver: generous for any P-matrix problem; guards against bugs and
  // breakdown.
  max_iterations_ = 50L * (n + 1) * std::min<long>(n + 1, 1000);
  has_matrix_ = true;
}

LcpResult BandedLcpSolver::solve(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z,
                                 Eigen::Ref<Vector> w) {
  if (!has_matrix_) throw InputError("banded LCP: solve called before set_matrix");
  const Index n = M_.rows();
  if (q.size() != n || z.size() != n || w.size() != n) {
    throw InputError(fmt::format(
        "banded LCP: solve: q, z and w have sizes {}, {} and {}; expected {} (the size of M)",
        q.size(), z.size(), w.size(), n));
  }
  double qmax = 0.0, qmin = n > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  for (Index i = 0; i < n; ++i) {
    if (!std::isfinite(q[i])) {
      throw InputError(fmt::format("banded LCP: solve: q[{}] = {} is not finite", i, q[i]));
    }
    qmax = std::max(qmax, std::abs(q[i]));
    qmin = std::min(qmin, q[i]);
  }
  LcpResult result;
  const block_pivoting::Tolerances tol = block_pivoting::tolerances(qmax, scale_);
  if (block_pivoting::zero_solves(qmin, tol)) {  // z = 0 solves it
    z.setZero();
    for (Index i = 0; i < n; ++i) w[i] = std::max(q[i], 0.0);
    return result;
  }

  // z doubles as the iterate: its entries on the active set are the warm start of the sweeps,
  // zeros elsewhere.
  for (Index i = 0; i < n; ++i) {
    active_[static_cast<std::size_t>(i)] = z[i] > 0.0 ? 1 : 0;
    if (!(z[i] > 0.0)) z[i] = 0.0;
  }

  // The principal solves on the whole vector: x = (z_A, w_F) with w = q + M z from the columns
  // of the active forces only (z is zero elsewhere).
  struct Policy {
    BandedLcpSolver& s;
    const Eigen::Ref<const Vector>& q;
    double* zd;
    block_pivoting::Tolerances tol;
    Index last = -1;  // the largest infeasible index

    bool infeasible(Index i) const {
      const bool in = s.active_[static_cast<std::size_t>(i)] != 0;
      return s.x_[i] < -(in ? tol.z : tol.w);
    }
    // A force that enters starts from the value that zeroes its own slack; one that leaves is 0.
    void flip(Index i) {
      unsigned char& a = s.active_[static_cast<std::size_t>(i)];
      a ^= 1;
      zd[i] = a ? -q[i] / s.diagonal_[i] : 0.0;
      if (!(zd[i] > 0.0)) zd[i] = 0.0;
    }
    int evaluate(long) {
      const Index n = s.M_.rows();
      s.set_.clear();
      for (Index i = 0; i < n; ++i) {
        if (s.active_[static_cast<std::size_t>(i)]) s.set_.push_back(static_cast<int>(i));
      }
      s.solve_active(q, zd);
      s.x_ = q;
      s.columns_.transpose_multiply_add(zd, s.x_.data());
      int count = 0;
      last = -1;
      for (Index i = 0; i < n; ++i) {
        if (s.active_[static_cast<std::size_t>(i)] != 0) s.x_[i] = zd[i];
        if (infeasible(i)) {
          ++count;
          last = i;
        }
      }
      return count;
    }
    void exchange_infeasible() {
      for (Index i = 0; i < s.M_.rows(); ++i)
        if (infeasible(i)) flip(i);
    }
    void exchange_largest_infeasible() { flip(last); }
    LcpError iteration_error(long iteration) const { return iteration_limit(iteration, s.M_.rows()); }
  };
  Policy policy{*this, q, z.data(), tol};
  result.pivots += block_pivoting::solve(policy, static_cast<int>(n), max_iterations_);
  block_pivoting::split_basic_vector(
      x_, n, [&](Index i) { return active_[static_cast<std::size_t>(i)] != 0; }, z, w);
  return result;
}

void BandedLcpSolver::rebuild_set() {
  set_.clear();
  for (std::size_t i = 0; i < active_.size(); ++i) {
    if (active_[i]) set_.push_back(static_cast<int>(i));
  }
}

void BandedLcpSolver::reset_active_set(const Eigen::Ref<const Vector>& z) {
  if (!has_matrix_) throw InputError("banded LCP: reset_active_set called before set_matrix");
  if (z.size() != M_.rows()) {
    throw InputError(fmt::format("banded LCP: reset_active_set: z has size {}, expected {}",
                                 z.size(), M_.rows()));
  }
  for (Index i = 0; i < z.size(); ++i) active_[static_cast<std::size_t>(i)] = z[i] > 0.0 ? 1 : 0;
  rebuild_set();
}

LcpResult BandedLcpSolver::solve_forces(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z) {
  if (!has_matrix_) throw InputError("banded LCP: solve_forces called before set_matrix");
  const Index n = M_.rows();
  if (q.size() != n || z.size() != n) {
    throw InputError(fmt::format("banded LCP: solve_forces: q and z have sizes {} and {}; "
                                 "expected {}",
                                 q.size(), z.size(), n));
  }
  LcpResult result;
  double qmax = 0.0;
  negative_.clear();
  for (Index i = 0; i < n; ++i) {
    qmax = std::max(qmax, std::abs(q[i]));
    if (q[i] < 0.0) negative_.push_back(static_cast<int>(i));
  }
  const block_pivoting::Tolerances tol = block_pivoting::tolerances(qmax, scale_);
  double* zd = z.data();
  // As solve(): when no q_i is below -tol, z = 0 (and that is not counted as pivots).
  bool all_feasible = true;
  for (int i : negative_) all_feasible = all_feasible && q[i] >= -tol.w;
  if (all_feasible) {
    for (int j : set_) {
      zd[j] = 0.0;
      active_[static_cast<std::size_t>(j)] = 0;
    }
    set_.clear();
    return result;
  }

  // The principal solves on the springs near contact: only the indices with q_i < 0 and those
  // within the band of an active one can be infeasible; flips_ collects them.
  struct Policy {
    BandedLcpSolver& s;
    const Eigen::Ref<const Vector>& q;
    double* zd;
    block_pivoting::Tolerances tol;

    int evaluate(long) {
      if (s.set_.empty()) {
        // z = 0: feasible unless some q_i < -tol.
        s.flips_.clear();
        for (int i : s.negative_) {
          if (q[i] < -tol.w) s.flips_.push_back(i);
        }
        return static_cast<int>(s.flips_.size());
      }
      s.solve_active(q, zd);
      // The slacks w_i = q_i + (M z)_i of the free indices that can be negative: those within
      // the band of an active one (rows j - upper .. j + lower of an active j) and those with
      // q_i < 0. Each in a band is one row of M against z (zero outside the active set), so the
      // rows are independent of one another; outside every band (M z)_i = 0 and w_i = q_i. The
      // active set and negative_ are ascending, so one walk visits every candidate once.
      s.flips_.clear();
      for (int j : s.set_) {
        if (zd[j] < -tol.z) s.flips_.push_back(j);
      }
      const Index rows = s.M_.rows();
      std::vector<int>& candidates = s.touched_;
      candidates.clear();
      const auto candidate = [&](Index i) {
        if (!s.active_[static_cast<std::size_t>(i)]) candidates.push_back(static_cast<int>(i));
      };
      Index next = 0;      // rows below it are listed
      std::size_t n = 0;   // into negative_
      const auto negatives_below = [&](Index end) {  // between bands: w_i = q_i
        for (; n < s.negative_.size() && s.negative_[n] < end; ++n) {
          const int i = s.negative_[n];
          if (i >= next && !s.active_[static_cast<std::size_t>(i)] && q[i] < -tol.w) {
            s.flips_.push_back(i);
          }
        }
      };
      for (int j : s.set_) {
        const Index begin = std::max(next, j - s.upper_);
        const Index end = std::min(rows, j + s.lower_ + 1);
        if (begin >= end) continue;
        negatives_below(begin);
        for (Index i = begin; i < end; ++i) candidate(i);
        next = end;
      }
      negatives_below(rows);
      s.M_.multiply_listed_rows(zd, candidates.data(), static_cast<Index>(candidates.size()),
                                s.next_.data());
      for (std::size_t c = 0; c < candidates.size(); ++c) {
        const int i = candidates[c];
        if (q[i] + s.next_[c] < -tol.w) s.flips_.push_back(i);
      }
      return static_cast<int>(s.flips_.size());
    }
    void exchange_infeasible() { flip(); }
    void exchange_largest_infeasible() {
      const int last = *std::max_element(s.flips_.begin(), s.flips_.end());
      s.flips_.assign(1, last);
      flip();
    }
    // Switches the indices in flips_ and forms the new active set, ascending: the old one
    // without the leavers, merged with the entrants.
    void flip() {
      for (int i : s.flips_) {
        unsigned char& a = s.active_[static_cast<std::size_t>(i)];
        a ^= 1;
        zd[i] = a ? std::max(0.0, -q[i] / s.diagonal_[i]) : 0.0;
      }
      std::sort(s.flips_.begin(), s.flips_.end());
      std::vector<int>& merged = s.touched_;  // reused as scratch
      merged.clear();
      std::size_t a = 0, b = 0;
      while (a < s.set_.size() || b < s.flips_.size()) {
        if (b == s.flips_.size() || (a < s.set_.size() && s.set_[a] < s.flips_[b])) {
          merged.push_back(s.set_[a++]);
        } else if (a == s.set_.size() || s.flips_[b] < s.set_[a]) {
          merged.push_back(s.flips_[b++]);  // entered
        } else {
          ++a;  // left
          ++b;
        }
      }
      s.set_.swap(merged);
    }
    LcpError iteration_error(long iteration) const { return iteration_limit(iteration, s.M_.rows()); }
  };
  Policy policy{*this, q, zd, tol};
  result.pivots += block_pivoting::solve(policy, static_cast<int>(n), max_iterations_);
  for (int j : set_) zd[j] = std::max(zd[j], 0.0);
  return result;
}

void BandedLcpSolver::solve_active(const Eigen::Ref<const Vector>& q, double* z) {
  if (set_.empty()) return;
  if (iterate_ && jacobi_sweeps(q, z)) return;
  factorize_and_solve(q, z);
}

bool BandedLcpSolver::jacobi_sweeps(const Eigen::Ref<const Vector>& q, double* z) {
  // Jacobi sweeps: every update of a sweep is formed from the previous sweep's forces and
  // written after, so the rows are independent (Gauss-Seidel's are a chain of latencies, and its
  // vector loads of forces just stored stall on the store buffer). On a strictly diagonally
  // dominant M both contract by at most the dominance ρ per sweep (in the largest entry).
  const auto N = set_.size();
  const double stop_factor = error_per_move(dominance_);
  for (int sweep = 0; sweep < options_.max_sweeps; ++sweep) {
    ++sweeps_;
    // Every row product is formed before any force is written.
    M_.multiply_listed_rows(z, set_.data(), static_cast<Index>(N), next_.data());
    double moved = 0.0, largest = 0.0;
    for (std::size_t a = 0; a < N; ++a) {
      const int i = set_[a];
      const double update = -(q[i] + next_[a]) * inverse_diagonal_[i];
      z[i] += update;
      moved = std::max(moved, std::abs(update));
      largest = std::max(largest, std::abs(z[i]));
    }
    if (moved * stop_factor <= kSweepTol * largest) return true;
  }
  return false;
}

void BandedLcpSolver::factorize_and_solve(const Eigen::Ref<const Vector>& q, double* z) {
  const Index N = static_cast<Index>(set_.size());
  const Index lo = lower_, up = upper_, W = lower_ + upper_ + 1;
  const auto at = [&](Index a, Index b) -> double& {
    return lu_[static_cast<std::size_t>(a * W + (b - a + lo))];
  };
  // Elimination without pivoting never changes earlier rows, so the factors of the rows before
  // the first position where the active set differs from the factored one stay valid, except the
  // entries of the last `upper` of those rows that lie in the changed columns: factorisation
  // restarts `upper` rows before the first difference.
  Index p0 = 0;
  const Index common = std::min<Index>(N, static_cast<Index>(factored_.size()));
  while (p0 < common && set_[static_cast<std::size_t>(p0)] == factored_[static_cast<std::size_t>(p0)]) {
    ++p0;
  }
  if (p0 < N || static_cast<Index>(factored_.size()) != N) {
    p0 = std::max<Index>(0, p0 - up);
    for (Index a = p0; a < N; ++a) {
      const Index i = set_[static_cast<std::size_t>(a)];
      for (Index b = std::max<Index>(0, a - lo); b <= std::min(N - 1, a + up); ++b) {
        at(a, b) = M_.coeff(i, set_[static_cast<std::size_t>(b)]);
      }
    }
    const double tiny = kSingularTol * static_cast<double>(W) * scale_;
    for (Index k = std::max<Index>(0, p0 - lo); k < N; ++k) {
      const double pivot = at(k, k);
      if (k >= p0 && !(pivot > tiny)) {
        factored_.clear();
        throw LcpError(fmt::format(
            "banded block pivoting: pivot {} of the principal block for {} active springs is {} "
            "(M is not a P-matrix?)",
            k, N, pivot));
      }
      for (Index a = std::max(k + 1, p0); a <= std::min(N - 1, k + lo); ++a) {
        double& l = at(a, k);
        if (l == 0.0) continue;
        l /= pivot;
        for (Index b = k + 1; b <= std::min(N - 1, k + up); ++b) at(a, b) -= l * at(k, b);
      }
    }
    factorized_rows_ += N - p0;
    factored_ = set_;
  }
  for (Index a = 0; a < N; ++a) {
    double s = -q[set_[static_cast<std::size_t>(a)]];
    for (Index k = std::max<Index>(0, a - lo); k < a; ++k) s -= at(a, k) * rhs_[static_cast<std::size_t>(k)];
    rhs_[static_cast<std::size_t>(a)] = s;
  }
  for (Index a = N - 1; a >= 0; --a) {
    double s = rhs_[static_cast<std::size_t>(a)];
    for (Index b = a + 1; b <= std::min(N - 1, a + up); ++b) s -= at(a, b) * rhs_[static_cast<std::size_t>(b)];
    rhs_[static_cast<std::size_t>(a)] = s / at(a, a);
  }
  for (Index a = 0; a < N; ++a) z[set_[static_cast<std::size_t>(a)]] = rhs_[static_cast<std::size_t>(a)];
}

bool is_p_matrix(const BandedMatrix& M, std::string* why) {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (M.rows() != M.cols()) {
    *why = fmt::format("M is {}x{}: not square", M.rows(), M.cols());
    return false;
  }
  const Index n = M.rows();
  bool dominant = true;
  for (Index i = 0; i < n && dominant; ++i) {
    const double* a = M.row_values(i);
    double off = 0.0;
    for (Index k = 0; k < M.width(); ++k) {
      if (M.first_column(i) + k != i) off += std::abs(a[k]);
    }
    const double d = M.coeff(i, i);
    dominant = d > 0.0 && off < d;
  }
  if (dominant) return true;
  // Banded Cholesky of the symmetric part.
  const Index b = std::max(M.lower_bandwidth(), M.upper_bandwidth());
  const Index W = b + 1;
  std::vector<double> L(static_cast<std::size_t>(n * W), 0.0);  // L(i, j), j in [i-b, i]
  const auto at = [&](Index i, Index j) -> double& {
    return L[static_cast<std::size_t>(i * W + (j - i + b))];
  };
  for (Index i = 0; i < n; ++i) {
    for (Index j = std::max<Index>(0, i - b); j <= i; ++j) {
      double s = 0.5 * (M.coeff(i, j) + M.coeff(j, i));
      for (Index k = std::max<Index>(0, i - b); k < j; ++k) s -= at(i, k) * at(j, k);
      if (j < i) {
        at(i, j) = s / at(j, j);
      } else if (s > 0.0) {
        at(i, i) = std::sqrt(s);
      } else {
        *why = fmt::format(
            "M is neither strictly diagonally dominant with a positive diagonal nor has a "
            "positive definite symmetric part (pivot {} of its Cholesky factorisation is {})",
            i, s);
        return false;
      }
    }
  }
  return true;
}

}  // namespace pwl
