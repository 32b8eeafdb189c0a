#pragma once
// The precise-integration stepper: advances (x, x', P) by one step of fixed size η using the
// constant operators of pim_step_operators.hpp and one LCP per step (He, Gao & Zhong 2018).
//
// It is a template over the number of degrees of freedom and of springs so that a 5-mass study
// runs on fixed-size Eigen types (no heap, unrolled products); PrecisePropagator<> is the
// run-time-sized version. Time is kept as t_origin + k η with an integer step count, so that a
// million steps land on kT exactly rather than accumulating rounding.
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/LU>
#include <utility>

#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/lcp_solver.hpp"
#include "pwl/pim_step_operators.hpp"

namespace pwl {

template <int Dofs = Eigen::Dynamic, int Springs = Eigen::Dynamic>
class PrecisePropagator {
 public:
  static constexpr int kStateSize = Dofs == Eigen::Dynamic ? Eigen::Dynamic : 2 * Dofs;
  using StateVector = Eigen::Matrix<double, kStateSize, 1>;
  using ForceVector = Eigen::Matrix<double, Springs, 1>;
  using TransitionMatrix = Eigen::Matrix<double, kStateSize, kStateSize>;
  using ForceMatrix = Eigen::Matrix<double, kStateSize, Springs>;
  using GapMatrix = Eigen::Matrix<double, Springs, Dofs>;

  // Takes the step's operators and an LCP solver (told the step's matrix here). Throws
  // InputError when the sizes do not match the template's or the step's LCP matrix is not a
  // P-matrix (the step is too large for the contact stiffness).
  PrecisePropagator(const PimStepOperators& ops, std::unique_ptr<LcpSolver> solver,
                    double divergence_bound = 1e12)
      : n_(ops.directions.rows()),
        eta_(ops.step),
        bound_(divergence_bound),
        solver_(std::move(solver)) {
    const Index m = ops.directions.cols();
    if ((Dofs != Eigen::Dynamic && n_ != Dofs) || (Springs != Eigen::Dynamic && m != Springs)) {
      throw InputError(fmt::format("a {}-dof, {}-spring structure given to a stepper for {} dofs "
                                   "and {} springs",
                                   n_, m, Dofs, Springs));
    }
    transition_ = ops.transition;
    force_now_ = ops.force_now;
    force_next_ = ops.force_next;
    gap_rows_ = ops.stiffnesses.asDiagonal() * ops.directions.transpose();  // K2 W^T
    gap_offset_ = ops.stiffnesses.cwiseProduct(ops.gaps);                 // K2 Δ
    for (const HarmonicResponse& h : ops.harmonics) {
      harmonics_.push_back({h.omega, h.sin_response, h.cos_response});
    }
    std::string why;
    if (m > 0 && !is_p_matrix(ops.lcp_matrix, &why)) {
      throw InputError(fmt::format(
          "step = {}: the step's LCP matrix is not a P-matrix ({}), so the spring forces are not "
          "unique; use a smaller step",
          eta_, why));
    }
    solver_->set_matrix(ops.lcp_matrix);
    lcp_matrix_ = ops.lcp_matrix;
    state_ = StateVector::Zero(2 * n_);
    bar_ = state_;
    forces_ = ForceVector::Zero(m);
    next_forces_ = forces_;
    q_ = forces_;
    slack_ = forces_;
  }

  // Sets time and state; the spring forces follow from x (P = k max(0, g)).
  void set_state(double t, const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& v) {
    if (x.size() != n_ || v.size() != n_) {
      throw InputError(fmt::format("state has {} displacements and {} velocities, expected {}",
                                   x.size(), v.size(), n_));
    }
    if (!std::isfinite(t) || !x.allFinite() || !v.allFinite()) {
      throw InputError(fmt::format("initial state at t = {} has a non-finite entry", t));
    }
    origin_ = t;
    steps_ = 0;
    state_.head(n_) = x;
    state_.tail(n_) = v;
    // k max(0, W^T x - Δ) = max(0, K2 W^T x - K2 Δ)
    forces_ = (gap_rows_ * state_.head(n_) - gap_offset_).cwiseMax(0.0);
  }

  // One step of size η.
  void step() {
    const double t = time();
    bar_.noalias() = transition_ * state_;
    bar_.noalias() += force_now_ * forces_;
    for (const Harmonic& h : harmonics_) {
      bar_ += std::sin(h.omega * t) * h.sin_response + std::cos(h.omega * t) * h.cos_response;
    }
    // q = K2 (Δ - W^T x̄); warm start from the current forces.
    q_.noalias() = gap_offset_ - gap_rows_ * bar_.head(n_);
    next_forces_ = forces_;
    last_pivots_ = solver_->solve(q_, next_forces_, slack_).pivots;
    state_ = bar_;
    state_.noalias() += force_next_ * next_forces_;
    forces_.swap(next_forces_);
    ++steps_;
    const double largest = state_.cwiseAbs().maxCoeff();
    if (!(largest <= bound_)) {
      throw DivergenceError(fmt::format(
          "the motion blew up at t = {}: largest |x| or |x'| is {} (bound {})", time(), largest,
          bound_));
    }
  }

  // Multiplies `tangent` (2n x p, rows in state order [x; x']) by the Jacobian of the step just
  // taken: the exact tangent map of the piecewise-affine step. With R = K2 W^T [I 0], D the springs
  // touching at the start of the step and A those touching at its end,
  //
  //     J = (I + Φ_A M_AA⁻¹ R_A) (T + Ψ D R),
  //
  // because P_k = max(0, R v_k - K2 Δ) and P_A = M_AA⁻¹ (R_A v̄ - K2 Δ_A) with the active set
  // fixed. The force is continuous, so crossing a kink needs no jump matrix (Müller, "Calculation
  // of Lyapunov exponents for dynamic systems with discontinuities", Chaos Solitons Fractals 5
  // (1995) 1671-1681, shows the jump term vanishes for continuous vector fields).
  void apply_step_tangent(Matrix& tangent) const {
    if (tangent.rows() != 2 * n_) {
      throw InputError(fmt::format("tangent has {} rows, the state has {}", tangent.rows(), 2 * n_));
    }
    const Index m = forces_.size();
    // Y <- T Y + Ψ D R Y
    Matrix reaction = gap_rows_ * tangent.topRows(n_);  // R Y, m x p
    for (Index j = 0; j < m; ++j) {
      if (!(next_forces_[j] > 0.0)) reaction.row(j).setZero();
    }
    Matrix next = transition_ * tangent;
    next.noalias() += force_now_ * reaction;
    // Y <- Y + Φ_A M_AA⁻¹ R_A Y
    std::vector<Index> active;
    for (Index j = 0; j < m; ++j) {
      if (forces_[j] > 0.0) active.push_back(j);
    }
    if (!active.empty()) {
      const Index a = static_cast<Index>(active.size());
      Matrix block(a, a), rows(a, tangent.cols()), columns(2 * n_, a);
      const Matrix gap_next = gap_rows_ * next.topRows(n_);
      for (Index r = 0; r < a; ++r) {
        for (Index c = 0; c < a; ++c) block(r, c) = lcp_matrix_(active[r], active[c]);
        rows.row(r) = gap_next.row(active[r]);
        columns.col(r) = force_next_.col(active[r]);
      }
      next.noalias() += columns * block.partialPivLu().solve(rows);
    }
    tangent = std::move(next);
  }

  double time() const { return origin_ + static_cast<double>(steps_) * eta_; }
  double step_size() const { return eta_; }
  long step_count() const { return steps_; }
  Index dofs() const { return n_; }
  auto position() const { return state_.head(n_); }
  auto velocity() const { return state_.tail(n_); }
  const StateVector& state() const { return state_; }
  const ForceVector& spring_forces() const { return forces_; }
  int last_lcp_pivots() const { return last_pivots_; }

 private:
  struct Harmonic {
    double omega;
    StateVector sin_response;
    StateVector cos_response;
  };

  Index n_;
  double eta_;
  double bound_;
  std::unique_ptr<LcpSolver> solver_;
  TransitionMatrix transition_;
  ForceMatrix force_now_;
  ForceMatrix force_next_;
  GapMatrix gap_rows_;
  ForceVector gap_offset_;
  Matrix lcp_matrix_;
  std::vector<Harmonic> harmonics_;
  double origin_ = 0.0;
  long steps_ = 0;
  int last_pivots_ = 0;
  StateVector state_, bar_;
  ForceVector forces_, next_forces_, q_, slack_;
};

}  // namespace pwl
