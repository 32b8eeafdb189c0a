#pragma once
// The step's LCP, w = M z + q, z >= 0, w >= 0, z^T w = 0, for a banded M, in work linear in its
// size.
//
// Block principal pivoting (J. J. Júdice and F. M. Pires, "A block principal pivoting algorithm
// for large-scale strictly monotone linear complementarity problems", Computers & Operations
// Research 21 (1994) 587-596), warm-started from the previous step's active set, with the single
// principal pivoting of K. G. Murty ("Note on a Bard-type scheme for solving the complementarity
// problem", Opsearch 11 (1974) 123-130) as the fall-back that makes it finite on P-matrices; the
// same scheme as the dense solver of lcp_solver.hpp. What changes is how each active set A is
// solved: M_AA z_A = -q_A, and w_F = q_F + M_FA z_A. The principal submatrix of a banded matrix
// on any index set is banded with the same bandwidths (|a - b| <= |i_a - i_b|), so both cost
// O(m · bandwidth):
//
//  - When M is strictly diagonally dominant (every row's off-diagonal sum at most
//    dominance_limit times its diagonal, true of the step's matrix I + O(η²)), so is every M_AA,
//    and Jacobi sweeps over A converge with rate at most that ratio: a handful of sweeps reach
//    rounding, each O(|A| · width), started from the previous step's forces. (Jacobi rather
//    than Gauss-Seidel: its rows are independent, so a sweep runs at the speed of a product.)
//  - Otherwise M_AA is factorised without pivoting (a P-matrix has positive leading principal
//    minors, so every pivot is positive; a pivot that is not means M is not a P-matrix and is
//    reported). The factors of the previous active set are kept, and a new set refactorises only
//    from its first index that differs.
//
// The stepper's path (solve_forces) forms only the slacks that can be negative: the rows of M
// within the band of an active index, each one row of M against z, and the q_i < 0 elsewhere
// (whose slack is q_i), so an iteration costs O(m) simple operations plus
// O(|A| (lower + upper + 1) · width). From one step to the next almost
// every spring keeps its state, so the warm start is usually already the answer, or one block
// pivot away.
#include <string>
#include <vector>

#include "pwl/numerics/banded_matrix.hpp"
#include "pwl/numerics/lcp_solver.hpp"

namespace pwl {

struct BandedLcpOptions {
  // Iterate (Jacobi sweeps) when ρ = max_i Σ_{j≠i} |M_ij| / M_ii <= dominance_limit and
  // sweeps from a cold start reach rounding within max_sweeps (about 35 / -ln ρ of them);
  // factorise otherwise. Must be in [0, 1).
  double dominance_limit = 0.5;
  int max_sweeps = 200;  // per active set, before falling back to the factorisation
  bool is_valid(std::string* why) const;
};

class BandedLcpSolver final : public LcpSolver {
 public:
  explicit BandedLcpSolver(const BandedLcpOptions& options = {});

  std::string name() const override { return "banded block-pivoting"; }
  LcpAlgorithm algorithm() const override { return LcpAlgorithm::block_pivoting; }
  // The dense interface: keeps the band of M's non-zeros.
  void set_matrix(const Matrix& M) override;
  void set_matrix(const BandedMatrix& M);
  LcpResult solve(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z,
                  Eigen::Ref<Vector> w) override;

  // For a stepper: solves for q in place in z, warm-started from the active set of the previous
  // solve (or of reset_active_set), without forming the slacks w. z must be what that call left
  // (zero outside its active set) and q finite (not checked). Only the indices with q_i < 0 and
  // those within the band of an active one can be infeasible, so an iteration costs one pass
  // over q plus O((those + active) · width): with few springs in contact, a step's LCP costs
  // little more than reading q.
  LcpResult solve_forces(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z);
  // Takes the active set from z (the indices with z > 0).
  void reset_active_set(const Eigen::Ref<const Vector>& z);
  // The active set after the last solve (ascending indices).
  const std::vector<int>& active_set() const { return set_; }

  // Whether active-set systems are solved by Jacobi sweeps (M diagonally dominant enough).
  bool iterates() const { return iterate_; }
  // max_i Σ_{j≠i} |M_ij| / M_ii (infinity when a diagonal entry is not positive).
  double dominance() const { return dominance_; }
  long sweeps() const { return sweeps_; }                  // Jacobi sweeps so far
  long factorized_rows() const { return factorized_rows_; }  // rows eliminated so far

 private:
  void solve_active(const Eigen::Ref<const Vector>& q, double* z);
  void rebuild_set();
  bool jacobi_sweeps(const Eigen::Ref<const Vector>& q, double* z);
  void factorize_and_solve(const Eigen::Ref<const Vector>& q, double* z);

  BandedLcpOptions options_;
  BandedMatrix M_;
  BandedMatrix columns_;          // M^T: solve()'s w = q + M z from the columns of z
  bool has_matrix_ = false;
  bool iterate_ = false;
  double dominance_ = 0.0;
  double scale_ = 1.0;  // max |M_ij|
  Index lower_ = 0, upper_ = 0;
  long max_iterations_ = 0;
  long sweeps_ = 0;
  long factorized_rows_ = 0;
  Vector diagonal_;
  Vector inverse_diagonal_;       // 1 / M_ii (Jacobi sweeps)
  std::vector<unsigned char> active_;
  std::vector<int> set_;          // the active indices, ascending
  std::vector<int> factored_;     // the active set the factors in lu_ belong to
  std::vector<double> lu_;        // band LU of M_AA, (lower + upper + 1) per row
  std::vector<double> rhs_;
  std::vector<double> next_;      // row products: a sweep's new forces, or candidates' slacks
  Vector x_;                      // complementary basic vector
  // solve_forces: q_i < 0, flips, and the rows whose slack can be negative (also the scratch
  // of the merged active set).
  std::vector<int> negative_, touched_, flips_;
};

// Whether a banded M is a P-matrix by sufficient tests (as is_p_matrix of lcp_solver.hpp does
// for large matrices): strict diagonal dominance with a positive diagonal, or a positive
// definite symmetric part (banded Cholesky). Returns false and says why otherwise.
bool is_p_matrix(const BandedMatrix& M, std::string* why = nullptr);

}  // namespace pwl
