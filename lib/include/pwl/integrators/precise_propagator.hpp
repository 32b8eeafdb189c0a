#pragma once
// The precise-integration stepper: advances (x, x', P) by one step of fixed size η using the
// constant operators of pim_step_operators.hpp and one LCP per step (He, Gao & Zhong 2018).
//
// It is a template over the number of degrees of freedom and of springs so that a 5-mass study
// runs on fixed-size Eigen types (no heap, unrolled products); PrecisePropagator<> is the
// run-time-sized version. Time is kept as t_origin + k η with an integer step count, so that a
// million steps land on kT exactly rather than accumulating rounding.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/LU>
#include <utility>

#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/numerics/block_pivoting.hpp"
#include "pwl/numerics/lcp_solver.hpp"
#include "pwl/numerics/state_checks.hpp"
#include "pwl/integrators/pim_step_operators.hpp"

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
      harmonics_.push_back({h.omega, std::cos(h.omega * eta_), std::sin(h.omega * eta_), 0.0, 1.0,
                            h.sin_response, h.cos_response});
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
    if constexpr (kInlineLcp) {
      inline_lcp_ = solver_->algorithm() == LcpAlgorithm::block_pivoting;
      const double mmax = m > 0 ? lcp_matrix_.cwiseAbs().maxCoeff() : 0.0;
      lcp_scale_ = mmax > 0.0 ? mmax : 1.0;
      transforms_.resize(std::size_t{1} << Springs);
      transform_ready_.assign(std::size_t{1} << Springs, 0);
    }
    state_ = StateVector::Zero(2 * n_);
    bar_ = state_;
    forces_ = ForceVector::Zero(m);
    next_forces_ = forces_;
    q_ = forces_;
    slack_ = forces_;
  }

  // Sets time and state; the spring forces follow from x (P = k max(0, g)).
  void set_state(double t, const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& v) {
    check_initial_state(t, x, v, n_);
    origin_ = t;
    steps_ = 0;
    state_.head(n_) = x;
    state_.tail(n_) = v;
    // k max(0, W^T x - Δ) = max(0, K2 W^T x - K2 Δ)
    forces_ = (gap_rows_ * state_.head(n_) - gap_offset_).cwiseMax(0.0);
    forces_zero_ = !(forces_.array() > 0.0).any();
    anchor_harmonics();
  }

  // One step of size η.
  //
  // The hot loop of every long run, so it avoids work that does not change the result:
  //  - sin ωt_k and cos ωt_k are advanced by the fixed rotation through ωη (one 2x2 product)
  //    instead of calling sin and cos, and re-anchored to the exact values every
  //    kReanchorSteps steps, so the rotation's rounding never accumulates beyond a few ulps;
  //  - with every spring open (P_k = 0) the product Ψ P_k is skipped, and when the LCP's
  //    right-hand side q is non-negative the answer is P_{k+1} = 0 (the solver's own first
  //    test) without calling it, and Φ P_{k+1} is skipped as well.
  void step() {
    // lazyProduct: coefficient-wise, unrolled for fixed sizes (Eigen would otherwise call its
    // general matrix-vector kernel for more than 8 rows, which costs more than the product).
    bar_.noalias() = transition_.lazyProduct(state_);
    if (!forces_zero_) bar_.noalias() += force_now_.lazyProduct(forces_);
    for (Harmonic& h : harmonics_) {
      bar_ += h.sin_now * h.sin_response + h.cos_now * h.cos_response;
    }
    // q = K2 (Δ - W^T x̄); warm start from the current forces.
    q_.noalias() = gap_offset_ - gap_rows_.lazyProduct(bar_.head(n_));
    if (q_.size() == 0 || q_.minCoeff() >= 0.0) {
      next_forces_.setZero();
      last_pivots_ = 0;
      state_ = bar_;
      forces_.swap(next_forces_);
      forces_zero_ = true;
    } else {
      next_forces_ = forces_;
      if constexpr (kInlineLcp) {
        last_pivots_ = inline_lcp_ ? solve_inline() : solver_->solve(q_, next_forces_, slack_).pivots;
      } else {
        last_pivots_ = solver_->solve(q_, next_forces_, slack_).pivots;
      }
      state_ = bar_;
      state_.noalias() += force_next_.lazyProduct(next_forces_);
      forces_.swap(next_forces_);
      forces_zero_ = !(forces_.array() > 0.0).any();
    }
    ++steps_;
    advance_harmonics();
    const double largest = state_.cwiseAbs().maxCoeff();
    if (!(largest <= bound_)) throw_divergence(time(), largest, bound_);
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

  // The same map applied to one tangent vector y (2n), for fixed sizes (kInlineLcp): a Lyapunov
  // exponent λ1 by one vector costs about one more step instead of 2n matrix columns. The
  // matrix Φ_A M_AA⁻¹ R_A is computed once per active set A and kept.
  void apply_step_tangent_vector(StateVector& y) {
    static_assert(kInlineLcp, "apply_step_tangent_vector needs fixed sizes");
    ForceVector reaction = gap_rows_.lazyProduct(y.template head<kDofs>());
    bool any = false;
    for (Index j = 0; j < reaction.size(); ++j) {
      if (!(next_forces_[j] > 0.0)) {
        reaction[j] = 0.0;
      } else {
        any = true;
      }
    }
    StateVector next = transition_.lazyProduct(y);
    if (any) next.noalias() += force_now_.lazyProduct(reaction);
    unsigned mask = 0;
    for (Index j = 0; j < forces_.size(); ++j)
      if (forces_[j] > 0.0) mask |= 1u << j;
    if (mask != 0) {
      const StateVector correction = tangent_correction(mask).lazyProduct(next.template head<kDofs>());
      next += correction;
    }
    y = next;
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
  // A fixed number of springs (up to 12) with the block-pivoting solver: the LCP is solved here,
  // by the block principal pivoting of block_pivoting.hpp (Júdice & Pires 1994, warm-started from
  // the previous active set, with Murty's single pivoting as the fall-back that terminates on
  // P-matrices) as make_block_pivoting_solver() does, on fixed-size storage and without a virtual
  // call or the solver's input checks, whose inputs are known valid here. The transform T_A with
  // x = T_A q (z_A = -M_AA⁻¹ q_A, w_F = q_F - M_FA M_AA⁻¹ q_A) is computed once per active set A
  // met and kept.
  static constexpr bool kInlineLcp = Springs != Eigen::Dynamic && Springs <= 12;
  static constexpr int kInlineSprings = kInlineLcp ? Springs : 1;
  using LcpTransform = Eigen::Matrix<double, kInlineSprings, kInlineSprings, Eigen::RowMajor>;

  const LcpTransform& lcp_transform(unsigned mask) {
    LcpTransform& t = transforms_[mask];
    if (transform_ready_[mask]) return t;
    if (!block_pivoting::active_set_transform(lcp_matrix_, kInlineSprings, mask, t)) {
      throw LcpError(fmt::format("block pivoting: the principal block of the step's LCP matrix "
                                 "for active-set mask {} is singular (not a P-matrix?)",
                                 mask));
    }
    transform_ready_[mask] = 1;
    return t;
  }

  static constexpr int kDofs = kInlineLcp ? Dofs : 1;
  using TangentCorrection = Eigen::Matrix<double, 2 * kDofs, kDofs>;

  // Φ_A M_AA⁻¹ R_A for the active set `mask` (R = K2 W^T acting on the displacements).
  const TangentCorrection& tangent_correction(unsigned mask) {
    if (corrections_.empty()) {
      corrections_.resize(std::size_t{1} << kInlineSprings);
      correction_ready_.assign(std::size_t{1} << kInlineSprings, 0);
    }
    TangentCorrection& c = corrections_[mask];
    if (correction_ready_[mask]) return c;
    std::vector<Index> active;
    for (Index j = 0; j < kInlineSprings; ++j)
      if (mask >> j & 1u) active.push_back(j);
    const Index a = static_cast<Index>(active.size());
    Matrix block(a, a), rows(a, n_), columns(2 * n_, a);
    for (Index r = 0; r < a; ++r) {
      for (Index k = 0; k < a; ++k) block(r, k) = lcp_matrix_(active[r], active[k]);
      rows.row(r) = gap_rows_.row(active[r]);
      columns.col(r) = force_next_.col(active[r]);
    }
    c = columns * block.partialPivLu().solve(rows);
    correction_ready_[mask] = 1;
    return c;
  }

  // The principal solves of the inline LCP: x = T_A q_ with the kept transform of A.
  struct InlineLcpPolicy : block_pivoting::MaskedActiveSet {
    PrecisePropagator& p;
    block_pivoting::Tolerances tol;
    Eigen::Matrix<double, kInlineSprings, 1> x;

    InlineLcpPolicy(PrecisePropagator& propagator, const block_pivoting::Tolerances& t)
        : p(propagator), tol(t) {}
    int evaluate(long) {
      x.noalias() = p.lcp_transform(mask).lazyProduct(p.q_);
      return mark_infeasible(x, kInlineSprings, tol);
    }
    LcpError iteration_error(long iteration) const {
      return LcpError(fmt::format(
          "block pivoting: no solution after {} iterations (n = {}), the iteration limit "
          "(M is not a P-matrix?)",
          iteration, kInlineSprings));
    }
  };

  // Solves the step's LCP for q_ into next_forces_ (holding the warm start) and slack_; returns
  // the pivots.
  int solve_inline() {
    constexpr int n = kInlineSprings;
    const block_pivoting::Tolerances tol =
        block_pivoting::tolerances(q_.cwiseAbs().maxCoeff(), lcp_scale_);
    if (block_pivoting::zero_solves(q_.minCoeff(), tol)) {
      next_forces_.setZero();
      slack_ = q_.cwiseMax(0.0);
      return 0;
    }
    InlineLcpPolicy policy(*this, tol);
    for (int i = 0; i < n; ++i)
      if (next_forces_[i] > 0.0) policy.mask |= 1u << i;
    const long max_iter =
        50L * (n + 1) * (n + 1) + (n + 1) * ((1L << n) + block_pivoting::kBlockTries + 2);
    const int pivots = block_pivoting::solve(policy, n, max_iter);
    block_pivoting::split_basic_vector(
        policy.x, n, [&](Index i) { return (policy.mask >> i & 1u) != 0; }, next_forces_, slack_);
    return pivots;
  }

  // Harmonic loads are re-anchored to exact sin and cos after this many rotations.
  static constexpr long kReanchorSteps = 256;

  struct Harmonic {
    double omega;
    double cos_step;  // cos ωη
    double sin_step;  // sin ωη
    double sin_now;   // sin ω t for the current time t
    double cos_now;   // cos ω t
    StateVector sin_response;
    StateVector cos_response;
  };

  void anchor_harmonics() {
    const double t = time();
    for (Harmonic& h : harmonics_) {
      h.sin_now = std::sin(h.omega * t);
      h.cos_now = std::cos(h.omega * t);
    }
  }

  // sin ω(t + η) = sin ωt cos ωη + cos ωt sin ωη, cos ω(t + η) = cos ωt cos ωη - sin ωt sin ωη.
  void advance_harmonics() {
    if (steps_ % kReanchorSteps == 0) {
      anchor_harmonics();
      return;
    }
    for (Harmonic& h : harmonics_) {
      const double s = h.sin_now, c = h.cos_now;
      h.sin_now = s * h.cos_step + c * h.sin_step;
      h.cos_now = c * h.cos_step - s * h.sin_step;
    }
  }

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
  bool forces_zero_ = true;  // every entry of forces_ is 0
  bool inline_lcp_ = false;  // kInlineLcp and the solver is block pivoting
  double lcp_scale_ = 1.0;   // max |M_ij| of the LCP matrix
  std::vector<LcpTransform> transforms_;
  std::vector<unsigned char> transform_ready_;
  std::vector<TangentCorrection> corrections_;
  std::vector<unsigned char> correction_ready_;
  StateVector state_, bar_;
  ForceVector forces_, next_forces_, q_, slack_;
};

}  // namespace pwl
