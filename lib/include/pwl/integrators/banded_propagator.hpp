#pragma once
// The banded precise-integration stepper: advances (x, x', P) by one step of fixed size η with the
// banded operators of banded_step_operators.hpp and one banded LCP per step, in work and memory
// O(n q) (He, Gao & Zhong 2018, §2-3; the step of precise_propagator.hpp with every operator
// banded).
//
// One step sweeps the interleaved state tile by tile (a few thousand rows, which stay in cache):
// v̄ = T v (each row a dot product over its band), the harmonic terms with the divergence check,
// and the LCP's right-hand side q from the displacement rows just formed. It then adds Ψ P_k,
// solves the LCP in place warm-started from the current forces, and adds Φ P_{k+1}. Usually few
// springs are in contact; Ψ P and Φ P then add only the columns of the springs whose force is
// not zero (work O(contacts · q) instead of O(n q)) and the LCP only looks at the springs near
// contact, so a step costs about one banded product T v plus a read of q: measured, 2 to 3 times
// the bare product (`pwl bench scaling`). Time is t_origin + k η with an integer step count, as
// in the dense stepper.
#include <algorithm>
#include <vector>

#include "pwl/numerics/banded_lcp_solver.hpp"
#include "pwl/integrators/banded_step_operators.hpp"

namespace pwl {

class BandedPropagator {
 public:
  // Takes the step's operators. Throws InputError when the step's LCP matrix fails the P-matrix
  // tests of banded_lcp_solver.hpp (the step is too large for the contact stiffness).
  BandedPropagator(BandedStepOperators ops, const BandedLcpOptions& lcp = {},
                   double divergence_bound = 1e12);

  // Sets time and state; the spring forces follow from x (P = k max(0, g)).
  void set_state(double t, const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& v);
  // One step of size η. Throws DivergenceError when the state leaves the divergence bound or
  // stops being finite, LcpError when the LCP cannot be solved.
  void step();

  double time() const { return origin_ + static_cast<double>(steps_) * ops_.step; }
  double step_size() const { return ops_.step; }
  long step_count() const { return steps_; }
  Index dofs() const { return n_; }
  // The interleaved state [x_0, x_0', x_1, x_1', ...].
  const Vector& state() const { return state_; }
  void position(Vector& x) const;
  void velocity(Vector& v) const;
  // Spring forces in the structure's numbering.
  Vector spring_forces() const;
  int last_lcp_pivots() const { return last_pivots_; }
  // The step's operators; the harmonic response vectors have moved into harmonic_matrix().
  const BandedStepOperators& operators() const { return ops_; }
  // Row r: h_sin and h_cos of each load group (in the order of operators().harmonics).
  const BandedMatrix& harmonic_matrix() const { return harmonics_; }
  const BandedLcpSolver& lcp_solver() const { return solver_; }
  // Bytes held by the operators and the work vectors.
  std::size_t memory_bytes() const;

 private:
  // Spring j (banded numbering) reads at most two displacements.
  struct SpringRow {
    Index dof_a, dof_b;  // dof_b = -1: ground
    double k_a, k_b;     // entries of K2 W^T
    double offset;       // k Δ
  };

  // Rows of the interleaved state per tile of the step's sweep (2 x 2048 masses: the tile of v̄
  // and the state it reads stay in the second-level cache).
  static constexpr Index kTileRows = 4096;

  Index final_dof(int j) const {
    const SpringRow& r = springs_[static_cast<std::size_t>(j)];
    return std::max(r.dof_a, r.dof_b);
  }
  // q_j = k Δ - K2 W^T x̄ for spring j, from v̄.
  void form_q(int j) {
    const SpringRow& sp = springs_[static_cast<std::size_t>(j)];
    double g = sp.k_a * bar_[2 * sp.dof_a];
    if (sp.dof_b >= 0) g += sp.k_b * bar_[2 * sp.dof_b];
    q_[j] = sp.offset - g;
  }

  BandedStepOperators ops_;
  // Ψ^T and Φ^T by rows (the columns of Ψ and Φ): Ψ P and Φ P from the springs in contact only.
  BandedMatrix force_now_columns_, force_next_columns_;
  // The harmonic responses as one 2n x 2h matrix (row r: h_sin and h_cos of each load group),
  // whose repeated rows are stored once: the load terms cost no memory traffic beyond v̄.
  BandedMatrix harmonics_;
  Vector harmonic_weights_;  // sin ωt_k, cos ωt_k per group
  BandedLcpSolver solver_;
  Index n_;
  double bound_;
  std::vector<SpringRow> springs_;
  // -K2 W^T on the interleaved state (spring rows repeat: stored once) and K2 Δ: q = K2 Δ + this
  // times v̄, formed tile by tile when the springs finish in order along the sweep.
  BandedMatrix gap_matrix_;
  Vector offsets_;
  std::vector<Index> tile_springs_end_;   // springs finished by the end of each tile (if in order)
  std::vector<int> by_final_dof_;          // springs by their larger degree of freedom
  std::vector<Index> dof_springs_start_;   // springs of dof d: dof_springs_[start[d] .. start[d+1])
  std::vector<int> dof_springs_;
  double origin_ = 0.0;
  long steps_ = 0;
  int last_pivots_ = 0;
  std::vector<int> acting_;  // springs whose force is not zero
  Vector state_, bar_;
  Vector forces_, q_;
};

}  // namespace pwl
