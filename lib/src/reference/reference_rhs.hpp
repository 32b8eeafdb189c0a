#pragma once
// The first-order right-hand side of a GapStructure for the reference integrators (private to
// pwl_core). With y = [x; x'],
//
//     y' = [x'; M^{-1} (f(t) - C x' - K x - W k max(0, W^T x - Δ))].
//
// Everything is prepared once so that a call allocates nothing: [K C] is one row-major sparse
// matrix applied to y in a single pass, the loads are per-frequency lists of nonzero entries (one
// sin/cos pair per frequency and call), the springs are a flat list, and M is inverted by the
// cheapest exact means its pattern allows (a reciprocal diagonal, a dense Cholesky factor for a
// small coupled M, a sparse Cholesky factor otherwise).
#include <memory>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

#include "pwl/model/gap_structure.hpp"

namespace pwl::reference_detail {

class GapRhs {
 public:
  // The structure must be valid (the caller validates it).
  explicit GapRhs(const GapStructure& structure);
  GapRhs(const GapRhs&) = delete;
  GapRhs& operator=(const GapRhs&) = delete;

  Index dofs() const { return n_; }
  Index spring_count() const { return static_cast<Index>(springs_.size()); }

  // dydt = y'(t, y). y and dydt have size 2 * dofs() and must not alias.
  void evaluate(const Vector& y, Vector& dydt, double t);
  // With modes set (one entry per spring, kept alive by the caller), spring j acts as the linear
  // spring P_j = k_j g_j when modes[j] > 0 and not at all otherwise, whatever the sign of g_j:
  // the smooth extension of one piece of the right-hand side across its kinks. nullptr restores
  // the true P_j = k_j max(0, g_j).
  void freeze_modes(const int* modes) { modes_ = modes; }
  long evaluations() const { return evaluations_; }

  // g_j = W_j^T x - Δ_j for the displacement part of y (the first dofs() entries).
  void gaps(const Vector& y, Vector& g) const;
  // W^T u for any u of size dofs() read from y at the given offset: the gap rates W^T x' (offset
  // dofs() in y) or, from y' = [x'; x''], the gap accelerations W^T x''.
  void gap_directional(const Vector& y, Index offset, Vector& out) const;
  // The size of the terms that make up g_j: |W_j^T x| + |Δ_j|, to scale thresholds on g_j.
  void gap_scales(const Vector& y, Vector& out) const;

  // Which of the three mass-matrix treatments was chosen: "diagonal", "dense" or "sparse".
  const char* mass_treatment() const;

 private:
  struct Spring {
    Index dof;
    Index other;  // -1: ground
    double direction;
    double stiffness;
    double gap;
  };
  struct LoadTerm {
    Index dof;
    double sin_coefficient;
    double cos_coefficient;
  };
  struct LoadGroup {
    double omega;
    std::vector<LoadTerm> terms;
  };
  enum class MassKind { diagonal, dense, sparse };

  void solve_mass(double* rhs);

  // One diagonal of K or C: entries (i, i + offset) for the rows i in [first, last), read from
  // y at column_base + i + offset (column_base: 0 for K, n for C).
  struct Diagonal {
    Index offset;
    Index column_base;
    Index first;
    Index last;
    Vector values;  // indexed by row
  };

  Index n_ = 0;
  // [K C] (n x 2n) is applied either by diagonals, when both are banded with few diagonals (a
  // chain: contiguous, vectorised loops), or as a compressed row-major sparse matrix.
  std::vector<Diagonal> diagonals_;
  Eigen::SparseMatrix<double, Eigen::RowMajor> kc_;
  std::vector<Spring> springs_;
  std::vector<LoadGroup> loads_;
  MassKind mass_kind_ = MassKind::diagonal;
  Vector inverse_mass_diagonal_;
  Eigen::LLT<Matrix> dense_mass_;
  std::unique_ptr<Eigen::SimplicialLLT<SparseMatrix>> sparse_mass_;
  Vector work_;
  const int* modes_ = nullptr;
  long evaluations_ = 0;
};

}  // namespace pwl::reference_detail
