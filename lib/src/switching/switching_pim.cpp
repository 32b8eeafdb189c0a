// The higher-order PIM of switching_pim.hpp: Hermite-Taylor force polynomial in smooth steps,
// Taylor-series pieces with located switches in the steps where a spring changes state.
#include "pwl/integrators/switching_pim.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <fmt/format.h>

#include "event/event_location.hpp"
#include "switching/switching_pim_detail.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/step_guard.hpp"
#include "integrators/fixed_sizes.hpp"
#include "integrators/fixed_step_count.hpp"
#include "pwl/numerics/block_pivoting.hpp"
#include "pwl/numerics/lcp_solver.hpp"
#include "pwl/numerics/state_checks.hpp"
#include "pwl/integrators/pim_step_operators.hpp"

namespace pwl {

bool SwitchingPimOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!check_step_settings(step, divergence_bound, why)) return false;
  if (force_degree < 0 || force_degree > 8) {
    *why = fmt::format("force_degree = {} must be in 0..8", force_degree);
    return false;
  }
  if (!(max_step_argument > 0.0)) {
    *why = fmt::format("max_step_argument = {} must be positive", max_step_argument);
    return false;
  }
  if (max_series_terms < 8 || max_series_terms > 200) {
    *why = fmt::format("max_series_terms = {} must be in 8..200", max_series_terms);
    return false;
  }
  return exponential.is_valid(why);
}

PolynomialForceIntegrals polynomial_force_integrals(const Matrix& H, double eta, const Matrix& G,
                                                    int degree,
                                                    const PreciseExponentialOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("precise exponential options: " + why);
  if (H.rows() != H.cols()) {
    throw InputError(fmt::format("H is {}x{}: it must be square", H.rows(), H.cols()));
  }
  if (G.cols() > 0 && G.rows() != H.rows()) {
    throw InputError(fmt::format("G has {} rows, H has {}", G.rows(), H.rows()));
  }
  if (!std::isfinite(eta) || eta <= 0.0) {
    throw InputError(fmt::format("step = {} must be positive and finite", eta));
  }
  if (degree < 0 || degree > 12) {
    throw InputError(fmt::format("degree = {} must be in 0..12", degree));
  }
  if (!H.allFinite() || !G.allFinite()) throw InputError("H or G has a non-finite entry");
  const Index n = H.rows();
  const Index m = G.cols();
  const int count = degree + 1;
  const int doublings = doublings_used(H, eta, 0.0, options);
  double tau = std::ldexp(eta, -doublings);

  // Taylor series at τ: T_a = Σ_{k>=1} (Hτ)^k/k!, Ξ̂_r = Σ_k H^k G τ^{k+1} r!/(k+r+1)!.
  Matrix Ta = Matrix::Zero(n, n);
  Matrix power = Matrix::Identity(n, n);
  Matrix HkG = G;
  std::vector<Matrix> moments(static_cast<std::size_t>(count), Matrix::Zero(n, m));
  for (int k = 0; k <= options.taylor_order; ++k) {
    if (k > 0) {
      power = power * H * (tau / k);
      Ta += power;
      HkG = H * HkG;
    }
    for (int r = 0; r < count; ++r) {
      // τ^{k+1} r!/(k+r+1)! = τ^{k+1} / ((r+1)(r+2)...(r+k+1))
      double c = 1.0;
      for (int i = 1; i <= k + 1; ++i) c *= tau / (r + i);
      moments[static_cast<std::size_t>(r)] += c * HkG;
    }
  }
  // Binomial coefficients C(r, i).
  std::vector<std::vector<double>> binomial(static_cast<std::size_t>(count));
  for (int r = 0; r < count; ++r) {
    auto& row = binomial[static_cast<std::size_t>(r)];
    row.assign(static_cast<std::size_t>(r + 1), 1.0);
    for (int i = 1; i < r; ++i) {
      row[static_cast<std::size_t>(i)] = binomial[static_cast<std::size_t>(r - 1)][static_cast<std::size_t>(i - 1)] +
                                        binomial[static_cast<std::size_t>(r - 1)][static_cast<std::size_t>(i)];
    }
  }
  Matrix stacked(n, count * m);
  for (int d = 0; d < doublings; ++d) {
    for (int r = 0; r < count; ++r) stacked.middleCols(r * m, m) = moments[static_cast<std::size_t>(r)];
    const Matrix TaX = Ta * stacked;
    std::vector<Matrix> next(static_cast<std::size_t>(count));
    for (int r = 0; r < count; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      // T Ξ̂_r + Ξ̂_r = T_a Ξ̂_r + 2 Ξ̂_r, then the lower moments from expanding (u + τ)^r.
      Matrix sum = TaX.middleCols(r * m, m) + 2.0 * moments[ru];
      for (int i = 0; i < r; ++i) sum += binomial[ru][static_cast<std::size_t>(i)] * moments[static_cast<std::size_t>(i)];
      next[ru] = std::ldexp(1.0, -r) * sum;
    }
    moments.swap(next);
    Ta = 2.0 * Ta + Ta * Ta;
    tau *= 2.0;
  }
  PolynomialForceIntegrals out;
  out.transition = std::move(Ta);
  out.transition.diagonal().array() += 1.0;
  out.moments = std::move(moments);
  return out;
}

namespace {

using switching_detail::kEpsilon;

struct LoadTerm {
  double omega;
  Vector sin_part;  // M⁻¹ times the load's sin part (velocity rows)
  Vector cos_part;
};

// Everything the stepper needs, at run-time size; the stepper copies it into its own types.
struct Operators {
  double eta = 0.0;
  int degree = 0;
  Matrix transition;
  std::vector<Matrix> correction;  // the coefficient of p_r (switching_detail::force_coefficients)
  Matrix phi;                      // the coefficient of P_{k+1}
  Matrix slope;                    // the coefficient of η P'_{k+1} (end_derivative)
  bool end_derivative = false;
  std::vector<HarmonicResponse> harmonics;
  Matrix stiffness_part, damping_part, force_part;  // -M⁻¹K, -M⁻¹C, -M⁻¹W
  Matrix gap_rows;                                  // W^T
  Vector gaps, stiffnesses;
  std::vector<LoadTerm> loads;
  Matrix lcp_matrix;
  double step_argument = 0.0;
};

Operators make_operators(const GapStructure& structure, const SwitchingPimOptions& o) {
  structure.validate();
  Operators ops;
  ops.eta = o.step;
  ops.degree = o.force_degree;
  const Index n = structure.dofs();
  const Index m = structure.spring_count();
  const Eigen::LLT<Matrix> mass{Matrix(structure.mass)};
  const Matrix W = structure.spring_directions();
  ops.stiffness_part = -mass.solve(Matrix(structure.stiffness));
  ops.damping_part = -mass.solve(Matrix(structure.damping));
  ops.force_part = m > 0 ? Matrix(-mass.solve(W)) : Matrix(n, 0);
  ops.gap_rows = W.transpose();
  ops.gaps = structure.spring_gaps();
  ops.stiffnesses = structure.spring_stiffnesses();
  for (const LoadGroup& g : structure.load_groups()) {
    ops.loads.push_back({g.omega, mass.solve(g.sin_part), mass.solve(g.cos_part)});
  }

  // η ω_max, ω_max the step guard's bound of |λ(H)| with every spring touching
  // (contact_frequency, step_guard.hpp), so that a step the guard passes is one this accepts.
  ops.step_argument = o.step * contact_frequency(structure).omega_max;
  if ((o.force_degree > 0 || o.end_derivative) && ops.step_argument > o.max_step_argument) {
    throw InputError(fmt::format(
        "step = {}: η ω_max = {:.3g} exceeds max_step_argument = {} (the contact is too stiff "
        "for the force derivatives at this step); use a step below {:.3g}, or force_degree = 0 "
        "with end_derivative = false",
        o.step, ops.step_argument, o.max_step_argument,
        o.step * o.max_step_argument / ops.step_argument));
  }

  Matrix G = Matrix::Zero(2 * n, m);
  if (m > 0) G.bottomRows(n) = ops.force_part;
  const int d = o.force_degree;
  ops.end_derivative = o.end_derivative;
  const PolynomialForceIntegrals pfi = polynomial_force_integrals(
      state_matrix(structure), o.step, G, d + (o.end_derivative ? 2 : 1), o.exponential);
  ops.transition = pfi.transition;
  switching_detail::ForceCoefficients c =
      switching_detail::force_coefficients(pfi.moments, d, o.end_derivative);
  ops.correction = std::move(c.correction);
  ops.phi = std::move(c.phi);
  ops.slope = std::move(c.slope);
  // The harmonic responses are the plain PIM's (exact for any step).
  ops.harmonics = make_pim_step_operators(structure, o.step, o.exponential).harmonics;
  ops.lcp_matrix = Matrix::Identity(m, m) -
                   ops.stiffnesses.asDiagonal() * ops.gap_rows * ops.phi.topRows(n);
  return ops;
}

template <int Dofs, int Springs>
class Stepper final
    : public SwitchingPim,
      private switching_detail::ModeSeries<Stepper<Dofs, Springs>, Eigen::Matrix<double, Dofs, 1>,
                                           Eigen::Matrix<double, Springs, 1>> {
  static constexpr int kState = Dofs == Eigen::Dynamic ? Eigen::Dynamic : 2 * Dofs;
  using State = Eigen::Matrix<double, kState, 1>;
  using Half = Eigen::Matrix<double, Dofs, 1>;
  using Force = Eigen::Matrix<double, Springs, 1>;
  using Series = switching_detail::ModeSeries<Stepper, Half, Force>;
  friend Series;
  using Series::gw_;
  using Series::phase_cos_;
  using Series::phase_sin_;
  using Series::ps_;
  using Series::screen_fails;
  using Series::size_series;
  using Series::switching_step;
  using Series::taylor;
  using Series::us_;
  using Series::xs_;
  static constexpr const char* kMethodName = "pim-switching";
  using StateSquare = Eigen::Matrix<double, kState, kState>;
  using StateForce = Eigen::Matrix<double, kState, Springs>;
  using HalfSquare = Eigen::Matrix<double, Dofs, Dofs>;
  using HalfForce = Eigen::Matrix<double, Dofs, Springs>;
  using ForceHalf = Eigen::Matrix<double, Springs, Dofs>;

 public:
  Stepper(const Operators& ops, const SwitchingPimOptions& o)
      : o_(o), n_(ops.stiffness_part.rows()), m_(ops.gap_rows.rows()), d_(ops.degree),
        eta_(ops.eta), solver_(make_lcp_solver(o.lcp_solver)) {
    if ((Dofs != Eigen::Dynamic && n_ != Dofs) || (Springs != Eigen::Dynamic && m_ != Springs)) {
      throw InputError(fmt::format("a {}-dof, {}-spring structure given to a stepper for {} dofs "
                                   "and {} springs",
                                   n_, m_, Dofs, Springs));
    }
    transition_ = ops.transition;
    for (const Matrix& c : ops.correction) correction_.push_back(c);
    phi_ = ops.phi;
    slope_ = ops.slope;
    end_derivative_ = ops.end_derivative;
    for (const HarmonicResponse& h : ops.harmonics) {
      harmonics_.push_back({h.omega, h.sin_response, h.cos_response});
    }
    stiffness_part_ = ops.stiffness_part;
    damping_part_ = ops.damping_part;
    force_part_ = ops.force_part;
    gap_rows_ = ops.gap_rows;
    gaps_ = ops.gaps;
    stiffnesses_ = ops.stiffnesses;
    spring_rows_ = ops.stiffnesses.asDiagonal() * ops.gap_rows;  // K2 W^T
    spring_offset_ = ops.stiffnesses.cwiseProduct(ops.gaps);     // K2 Δ
    abs_gap_rows_ = ops.gap_rows.cwiseAbs();
    for (const LoadTerm& l : ops.loads) loads_.push_back({l.omega, l.sin_part, l.cos_part});
    diagnostics_.step_argument = ops.step_argument;
    std::string why;
    if (m_ > 0 && !is_p_matrix(ops.lcp_matrix, &why)) {
      throw InputError(fmt::format("step = {}: the step's LCP matrix is not a P-matrix ({}); use "
                                   "a smaller step",
                                   eta_, why));
    }
    if (m_ > 0) solver_->set_matrix(ops.lcp_matrix);
    lcp_matrix_ = ops.lcp_matrix;
    const double mmax = m_ > 0 ? lcp_matrix_.cwiseAbs().maxCoeff() : 0.0;
    lcp_scale_ = mmax > 0.0 ? mmax : 1.0;
    inline_lcp_ = o.lcp_solver == LcpAlgorithm::block_pivoting;
    // The per-mode operators take at most one load group (its harmonic response and load in
    // the same group); more frequencies take the Taylor recursion in every step.
    mode_cached_ = kModeCache && loads_.size() <= 1 && harmonics_.size() == loads_.size() &&
                   m_ <= kMaxCachedSprings;
    if (mode_cached_) mode_ops_.resize(std::size_t{1} << m_);
    for (const Load& l : loads_) {
      rotations_.push_back({std::cos(l.omega * eta_), std::sin(l.omega * eta_)});
    }
    phases_ = Phases(0.0, 0.0, 1.0);
    const int terms = std::max(o.max_series_terms, d_ + 2) + 1;
    size_series(static_cast<std::size_t>(terms), n_, m_, static_cast<std::size_t>(d_ + 4));
    mode_ = Force::Zero(m_);
    signs_ = Force::Constant(m_, -1.0);
    state_ = State::Zero(2 * n_);
    bar_ = state_;
    z_ = Force::Zero(m_);
    lcp_x_ = z_;
    scaled_velocity_ = Half::Zero(n_);
    w_ = z_;
    q_ = z_;
    position_ = Vector::Zero(n_);
    velocity_ = position_;
    anchor_phases();
  }

  Method method() const override { return Method::pim_switching_dense; }
  std::string name() const override {
    return fmt::format("pim-{} (order {}{}, step {:.6g})", o_.locate_switches ? "switching" : "hermite",
                       d_ + (end_derivative_ ? 3 : 2), o_.locate_switches ? ", located switches" : "",
                       eta_);
  }
  Index dofs() const override { return n_; }
  double time() const override { return origin_ + static_cast<double>(steps_) * eta_; }
  const Vector& position() const override { return position_; }
  const Vector& velocity() const override { return velocity_; }
  IntegratorStats stats() const override { return stats_; }
  SwitchingPimDiagnostics diagnostics() const override { return diagnostics_; }

  void set_state(double t, const Vector& x, const Vector& v) override {
    check_initial_state(t, x, v, n_);
    origin_ = t;
    steps_ = 0;
    state_.head(n_) = x;
    state_.tail(n_) = v;
    // Touching where the gap is closed; a spring exactly at its kink starts slack and the first
    // step settles it from its derivatives.
    const Force g = gap_rows_ * state_.head(n_) - gaps_;
    for (Index j = 0; j < m_; ++j) set_mode(j, g[j] > 0.0);
    x_scale_ = x.cwiseAbs().maxCoeff();
    anchor_phases();
    sync();
  }

  void advance_to(double t_end, const StepObserver& observer) override {
    this->advance_steps(t_end, nullptr, observer);
  }

  // advance_to, and the tangent map of every step applied to `tangent` (see switching_pim.hpp).
  void advance_with_tangent(double t_end, Matrix& tangent, const StepObserver& observer) override {
    this->advance_steps(t_end, &tangent, observer);
  }

 private:
  struct Harmonic {
    double omega;
    State sin_response, cos_response;
  };
  struct Load {
    double omega;
    Half sin_part, cos_part;
  };
  struct Rotation {
    double cos_step, sin_step;  // cos ωη, sin ωη
  };
  // The phases sin ωt, cos ωt of the (at most one) load group and 1, and their coefficients.
  using Phases = Eigen::Vector3d;
  using StateLoad = Eigen::Matrix<double, kState, 3>;
  using ForceLoad = Eigen::Matrix<double, Springs, 3>;
  using ForceStateRows = Eigen::Matrix<double, Springs, kState, Eigen::RowMajor>;
  using ForceSquare = Eigen::Matrix<double, Springs, Springs>;
  // The smooth step in one mode, affine in the state v and in the phases (sin ωt, cos ωt of
  // the load group, 0 and 0 without one, and 1):
  //   bar = bar v + bar_load phases (the predicted end slope folded in),
  //   gw_r = gap[r] v + gap_load[r] phases (r = 0..d+1, the gap coefficients of the screen;
  //          row-major, so that each entry is one contiguous dot product; r = 0, 1 do not
  //          depend on the mode and the step computes them directly),
  //   p_r = touching gw_r for r >= 1 (touching = mode K2),
  //   slope at the end = slope_rows x'_{k+1} (η mode K2 W^T),
  // and the LCP transform of the mode as active set.
  struct ModeOps {
    StateSquare bar;
    StateLoad bar_load;
    std::vector<ForceStateRows> gap;
    std::vector<ForceLoad> gap_load;
    Force touching;
    ForceHalf slope_rows;
    ForceSquare lcp_transform;
    bool lcp_ready = false;
  };

  // The displacement and velocity halves of a state, as fixed-size blocks when the sizes are
  // fixed (a run-time-sized block would send the products to Eigen's general kernels).
  template <class V>
  static auto upper(V& v, Index n) {
    if constexpr (Dofs == Eigen::Dynamic) {
      return v.head(n);
    } else {
      return v.template head<Dofs>();
    }
  }
  template <class V>
  static auto lower(V& v, Index n) {
    if constexpr (Dofs == Eigen::Dynamic) {
      return v.tail(n);
    } else {
      return v.template tail<Dofs>();
    }
  }

  // A · x: coefficient-wise and fully unrolled for the fixed sizes (Eigen's general
  // matrix-vector kernel costs more than the arithmetic at these sizes), the kernel otherwise.
  template <class A, class X>
  static auto mul(const A& a, const X& x) {
    if constexpr (Dofs == Eigen::Dynamic) {
      return a * x;
    } else {
      return a.lazyProduct(x);
    }
  }

  void set_mode(Index j, bool on) {
    mode_[j] = on ? 1.0 : 0.0;
    signs_[j] = on ? 1.0 : -1.0;
    if (j < 64) {
      const std::uint64_t bit = std::uint64_t{1} << j;
      mode_mask_ = on ? (mode_mask_ | bit) : (mode_mask_ & ~bit);
    }
  }

  void sync() {
    position_ = state_.head(n_);
    velocity_ = state_.tail(n_);
  }

  // The hooks of ModeSeries (switching_pim_detail.hpp), which holds the Taylor recursion and the
  // pieces of switching steps.
  void gap_product(const Half& x, Force& out) const { out.noalias() = mul(gap_rows_, x); }
  void acceleration(const Half& x, const Half& u, const Force& p, Half& acc) const {
    acc.noalias() = mul(stiffness_part_, x);
    acc.noalias() += mul(damping_part_, u);
    acc.noalias() += mul(force_part_, p);
  }
  double kink_tolerance(Index j) const {
    return 64.0 * kEpsilon *
           (std::abs(gaps_[j]) + abs_gap_rows_.row(j).dot(xs_[0].head(n_).cwiseAbs()) +
            abs_gap_rows_.row(j).sum() * x_scale_);
  }
  void begin_piece() {}
  void end_pieces() {
    upper(state_, n_) = xs_[0];
    lower(state_, n_) = us_[0];
  }
  // No local switch corrections in the dense stepper (a small system gains nothing by them).
  void clear_local_records() {}
  [[noreturn]] void replay_local_step(Index, Matrix&) {
    throw std::logic_error("switching pim: a local step in the dense stepper's record");
  }

  // The series of the step from the current state: its start in xs_[0], us_[0].
  void start_series() {
    xs_[0] = upper(state_, n_);
    us_[0] = lower(state_, n_);
  }

  // One step. With fixed sizes and at most one load group, the smooth step uses the operators
  // of the current mode, in which everything before the LCP is affine in the state and in
  // sin ωt, cos ωt (see ModeOps); otherwise, and for every switching step, the Taylor recursion
  // of taylor().
  void step() {
    if (mode_cached_) {
      step_cached();
    } else {
      step_direct();
    }
  }

  // One step and its tangent map. A switching step maps the tangent piece by piece as it goes
  // (ModeSeries::tangent_piece); a smooth step is affine in the start state for the mode it
  // starts in and the LCP's active set, and tangent_smooth_step() applies its linear part after it.
  void step_with_tangent() {
    const ModeOps* op = mode_cached_ ? &mode_ops() : nullptr;
    start_mode_ = mode_;
    const long before = diagnostics_.switching_steps;
    step();
    if (diagnostics_.switching_steps == before && this->tangent_ != nullptr) tangent_smooth_step(op);
  }

  // The linear part of a smooth step applied to the tangent columns: the step's formula with the
  // loads and the spring offsets left out, the force derivatives p_r of the start mode, and the
  // LCP replaced by the linear solve on its active set A (the derivative of the LCP's solution
  // where A is locally constant: dz_A = -M_AA⁻¹ dq_A, dz = 0 elsewhere). With the mode's
  // operators (op) the part before the LCP is op->bar and op->gap, as in step_cached().
  void tangent_smooth_step(const ModeOps* op) {
    Matrix& Y = *this->tangent_;
    if (Y.cols() == 0) return;
    if constexpr (kModeCache) {
      if (op != nullptr && o_.locate_switches && op->lcp_ready) {
        tangent_smooth_cached(*op);
        return;
      }
    }
    const Index n = n_;
    const Vector touching = Vector(start_mode_).cwiseProduct(Vector(stiffnesses_));
    const auto last = d_ + (end_derivative_ ? 1 : 0);  // the last p_r the step uses
    if (op != nullptr) {
      t_bar_.noalias() = op->bar * Y;
      if (end_derivative_) {
        t_sum_.noalias() = static_cast<double>(d_ + 1) * (op->gap[static_cast<std::size_t>(d_ + 1)] * Y);
        for (int r = 1; r <= d_; ++r) {
          t_sum_.noalias() += static_cast<double>(r) * (op->gap[static_cast<std::size_t>(r)] * Y);
        }
        t_slope_.noalias() = touching.asDiagonal() * t_sum_;
      }
    } else {
      t_x_ = Y.topRows(n);
      t_u_ = Y.bottomRows(n);
      t_bar_.noalias() = transition_ * Y;
      if (end_derivative_) t_slope_.setZero(m_, Y.cols());
      for (int r = 0; r <= last; ++r) {
        t_sum_.noalias() = gap_rows_ * t_x_;
        t_p_.noalias() = touching.asDiagonal() * t_sum_;
        t_bar_.noalias() += correction_[static_cast<std::size_t>(r)] * t_p_;
        if (end_derivative_ && r >= 1) t_slope_ += static_cast<double>(r) * t_p_;
        if (r == last) break;
        const double f = eta_ / (r + 1);
        if (r < d_) {
          t_acc_.noalias() = stiffness_part_ * t_x_;
          t_acc_.noalias() += damping_part_ * t_u_;
          t_acc_.noalias() += force_part_ * t_p_;
        }
        t_x_ = f * t_u_;
        if (r < d_) t_u_ = f * t_acc_;
      }
    }
    if (m_ > 0) {
      // -dq = K2 W^T dbar_x.
      t_q_.noalias() = spring_rows_ * t_bar_.topRows(n);
      solve_active_set(t_q_, t_z_);
      Y = t_bar_;
      Y.noalias() += phi_ * t_z_;
    } else {
      Y = t_bar_;
    }
    if (end_derivative_ && o_.locate_switches && m_ > 0) {
      // The end-slope correction, with the slope of the new state (same mode at both ends).
      t_sum_.noalias() = gap_rows_ * Y.bottomRows(n);
      t_slope_ = (eta_ * Vector(mode_).cwiseProduct(Vector(stiffnesses_))).asDiagonal() * t_sum_ -
                 t_slope_;
      Y.noalias() += slope_ * t_slope_;
    }
  }

  // tangent_smooth_step() on the fixed sizes, column by column as step_cached() steps the state:
  // the mode's operators, and the LCP's active set (the mode, when switches are located) solved
  // by the mode's transform T_A (dz_A = (T_A dq)_A).
  void tangent_smooth_cached(const ModeOps& op) {
    Matrix& Y = *this->tangent_;
    for (Index c = 0; c < Y.cols(); ++c) {
      t_state_ = Y.col(c);
      t_state_bar_.noalias() = mul(op.bar, t_state_);
      if (end_derivative_) {
        t_force_.noalias() = mul(op.gap[static_cast<std::size_t>(d_ + 1)], t_state_);
        t_force_ *= static_cast<double>(d_ + 1);
        for (int r = 1; r <= d_; ++r) {
          t_force_sum_.noalias() = mul(op.gap[static_cast<std::size_t>(r)], t_state_);
          t_force_ += static_cast<double>(r) * t_force_sum_;
        }
        t_force_ = op.touching.cwiseProduct(t_force_);
      }
      // -dq = K2 W^T dbar_x, and T_A(-dq) = -dz on the active set.
      t_force_sum_.noalias() = mul(spring_rows_, upper(t_state_bar_, n_));
      t_force_dz_.noalias() = mul(op.lcp_transform, t_force_sum_);
      t_state_ = t_state_bar_;
      for (Index j = 0; j < m_; ++j) {
        if (mode_[j] > 0.0) t_state_ -= t_force_dz_[j] * phi_.col(j);
      }
      if (end_derivative_ && mode_mask_ != 0) {
        t_force_sum_.noalias() = mul(op.slope_rows, lower(t_state_, n_));
        t_force_ = t_force_sum_ - t_force_;
        for (Index j = 0; j < m_; ++j) {
          if (mode_[j] > 0.0) t_state_ += t_force_[j] * slope_.col(j);
        }
      }
      Y.col(c) = t_state_;
    }
  }

  // dz = 0 outside the last LCP's active set A = {z > 0}, dz_A = M_AA⁻¹ (-dq_A) for
  // minus_dq = -dq; the LU of M_AA is kept until A changes.
  void solve_active_set(const Matrix& minus_dq, Matrix& dz) {
    active_.clear();
    for (Index j = 0; j < m_; ++j) {
      if (z_[j] > 0.0) active_.push_back(j);
    }
    const auto a = static_cast<Index>(active_.size());
    if (!lu_valid_ || active_ != lu_active_) {
      Matrix block(a, a);
      for (Index i = 0; i < a; ++i) {
        for (Index k = 0; k < a; ++k) {
          block(i, k) = lcp_matrix_(active_[static_cast<std::size_t>(i)], active_[static_cast<std::size_t>(k)]);
        }
      }
      if (a > 0) active_lu_.compute(block);
      lu_active_ = active_;
      lu_valid_ = true;
    }
    dz.setZero(m_, minus_dq.cols());
    if (a == 0) return;
    t_rhs_.resize(a, minus_dq.cols());
    for (Index i = 0; i < a; ++i) t_rhs_.row(i) = minus_dq.row(active_[static_cast<std::size_t>(i)]);
    t_sol_.noalias() = active_lu_.solve(t_rhs_);
    for (Index i = 0; i < a; ++i) dz.row(active_[static_cast<std::size_t>(i)]) = t_sol_.row(i);
  }

  // The smooth step on the mode's combined operators: the same quantities as step_direct()
  // computes through the Taylor recursion, up to rounding.
  void step_cached() {
    const double t = time();
    const ModeOps& op = mode_ops();
    // The first two gap terms, W^T x and η W^T x', are the same in every mode.
    gw_[0].noalias() = mul(gap_rows_, upper(state_, n_));
    scaled_velocity_ = eta_ * lower(state_, n_);
    gw_[1].noalias() = mul(gap_rows_, scaled_velocity_);
    const auto terms = static_cast<std::size_t>(d_ + 2);
    for (std::size_t r = 2; r < terms; ++r) {
      gw_[r].noalias() = mul(op.gap[r], state_);
      gw_[r].noalias() += mul(op.gap_load[r], phases_);
    }
    if (o_.locate_switches && screen_fails()) {
      ++diagnostics_.screened;
      start_series();  // the data switching_step() continues
      taylor(t, eta_, d_ + 1, 0.0, false);
      switching_step(t, kMethodName);
      return;
    }
    bar_.noalias() = mul(op.bar, state_);
    bar_.noalias() += mul(op.bar_load, phases_);
    if (end_derivative_) {
      // The end slope η P'(t_{k+1}) the start's Taylor data predict, Σ_{r=1}^{d+1} r p_r with
      // p_r = mode K2 gw_r for r >= 1.
      slope_guess_ = static_cast<double>(d_ + 1) * gw_[static_cast<std::size_t>(d_ + 1)];
      for (int r = 1; r <= d_; ++r) {
        slope_guess_ += static_cast<double>(r) * gw_[static_cast<std::size_t>(r)];
      }
      slope_guess_ = op.touching.cwiseProduct(slope_guess_);
    }
    q_.noalias() = spring_offset_ - mul(spring_rows_, upper(bar_, n_));
    if (m_ > 0 && !solve_warm(op)) {
      z_ = mode_;
      stats_.lcp_pivots += solver_->solve(q_, z_, w_).pivots;
    }
    if (o_.locate_switches) {
      for (Index j = 0; j < m_; ++j) {
        if ((z_[j] > 0.0) != (mode_[j] > 0.0)) {
          ++diagnostics_.lcp_mismatches;
          start_series();
          taylor(t, eta_, d_ + 1, 0.0, false);
          switching_step(t, kMethodName);
          return;
        }
      }
    } else {
      for (Index j = 0; j < m_; ++j) set_mode(j, z_[j] > 0.0);
    }
    // Φ z and the slope correction over the springs that carry a force only: the others'
    // columns are multiplied by zero (few springs touch at a time).
    state_ = bar_;
    for (Index j = 0; j < m_; ++j) {
      if (z_[j] != 0.0) state_ += z_[j] * phi_.col(j);
    }
    if (end_derivative_ && o_.locate_switches && mode_mask_ != 0) {
      // Correct with the slope the new state gives (the mode is the same at both ends); both
      // slopes vanish on the slack springs.
      slope_guess_ = mul(op.slope_rows, lower(state_, n_)) - slope_guess_;
      for (Index j = 0; j < m_; ++j) {
        if (mode_[j] > 0.0) state_ += slope_guess_[j] * slope_.col(j);
      }
    }
    finish_step();
  }

  // The LCP for q_ when the block-pivoting solver's first iterate from the warm start (the
  // current mode) already solves it, as it does in every smooth step: z = 0 when q is
  // non-negative, else x = T_A q with the mode's transform. The first iteration of
  // block_pivoting.hpp with the solver's tolerances, without its input checks and the virtual
  // call. Returns false (z_ untouched) when it cannot decide: another solver, a non-finite q, or
  // an infeasible iterate, which the solver then pivots away.
  bool solve_warm(const ModeOps& op) {
    if (!inline_lcp_ || !op.lcp_ready) return false;
    double qmax = 0.0, qmin = std::numeric_limits<double>::infinity();
    for (Index i = 0; i < m_; ++i) {
      const double v = q_[i];
      if (!std::isfinite(v)) return false;
      qmax = std::max(qmax, std::abs(v));
      qmin = std::min(qmin, v);
    }
    const block_pivoting::Tolerances tol = block_pivoting::tolerances(qmax, lcp_scale_);
    if (block_pivoting::zero_solves(qmin, tol)) {
      z_.setZero();
      return true;
    }
    lcp_x_.noalias() = mul(op.lcp_transform, q_);
    block_pivoting::MaskedActiveSet set;
    set.mask = static_cast<std::uint32_t>(mode_mask_);
    if (set.mark_infeasible(lcp_x_, static_cast<int>(m_), tol) != 0) return false;
    for (Index i = 0; i < m_; ++i) z_[i] = mode_[i] > 0.0 ? std::max(lcp_x_[i], 0.0) : 0.0;
    return true;
  }

  void step_direct() {
    const double t = time();
    // Taylor data of the force over the step (and one more gap term for the screen).
    start_series();
    taylor(t, eta_, d_ + 1, 0.0, false);
    if (o_.locate_switches && screen_fails()) {
      // A spring may switch in this step: follow it with the series, which locates the switch
      // if there is one and is exact to rounding either way.
      ++diagnostics_.screened;
      switching_step(t, kMethodName);
      return;
    }
    bar_.noalias() = mul(transition_, state_);
    // The load phases at t were computed by taylor(); the groups are in the same order.
    for (std::size_t g = 0; g < harmonics_.size(); ++g) {
      bar_ += phase_sin_[g] * harmonics_[g].sin_response + phase_cos_[g] * harmonics_[g].cos_response;
    }
    if (end_derivative_) {
      // The end slope η P'(t_{k+1}) as the start's Taylor data predict it (one more term).
      const auto last = static_cast<std::size_t>(d_ + 1);
      ps_[last] = mode_.cwiseProduct(stiffnesses_.cwiseProduct(gw_[last]));
      slope_guess_ = static_cast<double>(d_ + 1) * ps_[last];
      for (int r = 1; r <= d_; ++r) slope_guess_ += static_cast<double>(r) * ps_[static_cast<std::size_t>(r)];
    }
    for (std::size_t r = 0; r < correction_.size(); ++r) bar_.noalias() += mul(correction_[r], ps_[r]);
    q_.noalias() = spring_offset_ - mul(spring_rows_, upper(bar_, n_));
    z_ = mode_;
    if (m_ > 0) stats_.lcp_pivots += solver_->solve(q_, z_, w_).pivots;
    if (o_.locate_switches) {
      for (Index j = 0; j < m_; ++j) {
        if ((z_[j] > 0.0) != (mode_[j] > 0.0)) {
          ++diagnostics_.lcp_mismatches;
          switching_step(t, kMethodName);
          return;
        }
      }
    } else {
      for (Index j = 0; j < m_; ++j) set_mode(j, z_[j] > 0.0);
    }
    state_ = bar_;
    state_.noalias() += mul(phi_, z_);
    if (end_derivative_ && o_.locate_switches) {
      // Correct with the slope the new state gives (the mode is the same at both ends).
      slope_guess_ = eta_ * mode_.cwiseProduct(stiffnesses_.cwiseProduct(mul(gap_rows_, lower(state_, n_)))) - slope_guess_;
      state_.noalias() += mul(slope_, slope_guess_);
    }
    finish_step();
  }

  void finish_step() {
    ++steps_;
    ++stats_.steps;
    ++diagnostics_.steps;
    advance_phases();
    const double largest = state_.cwiseAbs().maxCoeff();
    x_scale_ = std::max(x_scale_, upper(state_, n_).cwiseAbs().maxCoeff());
    if (!(largest <= o_.divergence_bound)) throw_divergence(time(), largest, o_.divergence_bound);
  }

  // sin ωt and cos ωt of the load group (the per-mode path takes at most one) at the step
  // start, in phases_. Advanced by the fixed rotation through ωη each step and re-anchored to
  // std::sin, std::cos every kReanchorSteps steps, so the rotation's rounding stays within a
  // few ulps (as the plain PIM's propagator does).
  void anchor_phases() {
    if (!mode_cached_ || loads_.empty()) return;
    const double t = time();
    phases_[0] = std::sin(loads_[0].omega * t);
    phases_[1] = std::cos(loads_[0].omega * t);
  }

  void advance_phases() {
    if (!mode_cached_ || loads_.empty()) return;
    if (steps_ % kReanchorSteps == 0) {
      anchor_phases();
      return;
    }
    const double sn = phases_[0], cs = phases_[1];
    const Rotation& rot = rotations_[0];
    phases_[0] = sn * rot.cos_step + cs * rot.sin_step;
    phases_[1] = cs * rot.cos_step - sn * rot.sin_step;
  }

  // The operators of the current mode, built the first time the mode is met.
  const ModeOps& mode_ops() {
    std::unique_ptr<ModeOps>& slot = mode_ops_[static_cast<std::size_t>(mode_mask_)];
    if (!slot) slot = build_mode_ops();
    return *slot;
  }

  // For the current mode, the smooth step's affine maps, found by running the recursion of
  // taylor() (h = η, terms up to d + 1) on the columns of [I_2n, phase terms]: the column of
  // sin ωt (cos ωt) of the load group is the response to that phase, the last column the
  // constant part (the spring offsets K2 Δ in p_0).
  std::unique_ptr<ModeOps> build_mode_ops() const {
    const Index n = n_, m = m_;
    const auto groups = static_cast<Index>(loads_.size());
    const Index cols = 2 * n + 2 * groups + 1;
    const Index first_phase = 2 * n, constant = cols - 1;
    const Vector mode = mode_;
    const Vector touching = mode.cwiseProduct(Vector(stiffnesses_));  // mode K2
    const Matrix W_t = gap_rows_;
    const Matrix K_part = stiffness_part_, C_part = damping_part_, F_part = force_part_;
    const auto terms = static_cast<std::size_t>(d_ + 2);
    std::vector<Matrix> xs(terms), us(terms), ps(terms), gw(terms);
    xs[0] = Matrix::Zero(n, cols);
    xs[0].leftCols(n).setIdentity();
    us[0] = Matrix::Zero(n, cols);
    us[0].middleCols(n, n).setIdentity();
    gw[0] = W_t * xs[0];
    std::vector<double> scale(loads_.size(), 1.0);
    for (int r = 0; r <= d_; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      ps[ru] = touching.asDiagonal() * gw[ru];
      if (r == 0) ps[ru].col(constant) -= mode.cwiseProduct(Vector(spring_offset_));
      const double f = eta_ / (r + 1);
      xs[ru + 1] = f * us[ru];
      gw[ru + 1] = W_t * xs[ru + 1];
      if (r == d_) break;
      Matrix acc = K_part * xs[ru] + C_part * us[ru] + F_part * ps[ru];
      for (std::size_t g = 0; g < loads_.size(); ++g) {
        // The cycle (S, C, -S, -C) of taylor() as coefficients of sin ωt and cos ωt.
        const Index cs = first_phase + 2 * static_cast<Index>(g), cc = cs + 1;
        const Vector sp = loads_[g].sin_part, cp = loads_[g].cos_part;
        const double a = scale[g];
        if (a != 0.0) {
          switch (r % 4) {
            case 0: acc.col(cs) += a * sp; acc.col(cc) += a * cp; break;
            case 1: acc.col(cs) -= a * cp; acc.col(cc) += a * sp; break;
            case 2: acc.col(cs) -= a * sp; acc.col(cc) -= a * cp; break;
            default: acc.col(cs) += a * cp; acc.col(cc) -= a * sp; break;
          }
        }
        scale[g] = a * loads_[g].omega * eta_ / (r + 1);
      }
      us[ru + 1] = f * acc;
    }
    const auto last = static_cast<std::size_t>(d_ + 1);
    ps[last] = touching.asDiagonal() * gw[last];

    // bar = T v + Σ_g (sin_g, cos_g responses) + Σ_r correction_r p_r.
    Matrix bar = Matrix::Zero(2 * n, cols);
    bar.leftCols(2 * n) = Matrix(transition_);
    for (std::size_t g = 0; g < harmonics_.size(); ++g) {
      const Index cs = first_phase + 2 * static_cast<Index>(g);
      bar.col(cs) += Vector(harmonics_[g].sin_response);
      bar.col(cs + 1) += Vector(harmonics_[g].cos_response);
    }
    for (std::size_t r = 0; r < correction_.size(); ++r) bar += Matrix(correction_[r]) * ps[r];

    auto out = std::make_unique<ModeOps>();
    // The phase columns in the order of phases_: sin, cos (zero without a load), 1.
    const auto phase_columns = [&](const Matrix& a) {
      Matrix b = Matrix::Zero(a.rows(), 3);
      b.leftCols(2 * groups) = a.middleCols(first_phase, 2 * groups);
      b.col(2) = a.col(constant);
      return b;
    };
    out->bar = bar.leftCols(2 * n);
    out->bar_load = phase_columns(bar);
    for (std::size_t r = 0; r < terms; ++r) {
      out->gap.push_back(gw[r].leftCols(2 * n));
      out->gap_load.push_back(phase_columns(gw[r]));
    }
    out->touching = touching;
    out->slope_rows = eta_ * touching.asDiagonal() * W_t;

    // The LCP transform of the mode as active set: x = T_A q with z_A = -M_AA⁻¹ q_A and
    // w_F = q_F - M_FA M_AA⁻¹ q_A; a singular M_AA is left to the solver, which reports it.
    Matrix transform;
    out->lcp_ready = block_pivoting::active_set_transform(lcp_matrix_, m, mode_mask_, transform);
    out->lcp_transform = transform;
    return out;
  }

  // The per-mode cache needs fixed sizes (products unrolled, at most 2^6 modes).
  static constexpr bool kModeCache = Dofs != Eigen::Dynamic && Springs != Eigen::Dynamic;
  static constexpr Index kMaxCachedSprings = 6;
  static constexpr long kReanchorSteps = 256;

  SwitchingPimOptions o_;
  Index n_, m_;
  int d_;
  double eta_;
  std::unique_ptr<LcpSolver> solver_;
  StateSquare transition_;
  std::vector<StateForce> correction_;  // coefficients of p_r (with the slope prediction)
  StateForce phi_;                      // ... of P_{k+1}
  StateForce slope_;                    // ... of η P'_{k+1}
  bool end_derivative_ = false;
  Force slope_guess_;
  std::vector<Harmonic> harmonics_;
  HalfSquare stiffness_part_, damping_part_;
  HalfForce force_part_;
  ForceHalf gap_rows_, spring_rows_, abs_gap_rows_;
  Force gaps_, stiffnesses_, spring_offset_;
  std::vector<Load> loads_;

  Force mode_, signs_;
  State state_, bar_;
  Force z_, w_, q_;
  double origin_ = 0.0;
  long steps_ = 0;
  double x_scale_ = 0.0;
  Vector position_, velocity_;
  IntegratorStats stats_;
  SwitchingPimDiagnostics diagnostics_;

  Matrix lcp_matrix_;
  double lcp_scale_ = 1.0;       // max |M_ij| of the LCP matrix
  bool inline_lcp_ = false;      // the solver is block pivoting
  bool mode_cached_ = false;     // step_cached() is used
  std::uint64_t mode_mask_ = 0;  // bit j: spring j touching (mode_[j] = 1)
  std::vector<std::unique_ptr<ModeOps>> mode_ops_;  // by mode_mask_
  std::vector<Rotation> rotations_;
  Phases phases_;  // sin ωt, cos ωt of the load group at the step start, and 1
  Force lcp_x_;
  Half scaled_velocity_;  // η x'

  // advance_with_tangent: the mode a step starts in, the active set of the LU kept for the
  // tangent's LCP solves, and scratch.
  Force start_mode_;
  std::vector<Index> active_, lu_active_;
  Eigen::PartialPivLU<Matrix> active_lu_;
  bool lu_valid_ = false;
  Matrix t_bar_, t_x_, t_u_, t_acc_, t_p_, t_sum_, t_slope_, t_q_, t_z_, t_rhs_, t_sol_;
  State t_state_, t_state_bar_;
  Force t_force_, t_force_sum_, t_force_dz_;
};

// Fixed-size steppers for the square cases of up to detail::kFixedSizes masses
// (integrators/fixed_sizes.hpp), the dynamic one otherwise.
template <int N>
std::unique_ptr<SwitchingPim> make_fixed(const Operators& ops, const SwitchingPimOptions& o) {
  if constexpr (N > 0) {
    if (ops.gap_rows.cols() == N && ops.gap_rows.rows() == N) {
      return std::make_unique<Stepper<N, N>>(ops, o);
    }
    return make_fixed<N - 1>(ops, o);
  } else {
    return std::make_unique<Stepper<Eigen::Dynamic, Eigen::Dynamic>>(ops, o);
  }
}

}  // namespace

std::unique_ptr<SwitchingPim> make_switching_pim(const GapStructure& structure,
                                                 const SwitchingPimOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("switching pim options: " + why);
  structure.validate();
  if (structure.load_groups().size() > 16) {
    throw InputError(fmt::format("loads: {} distinct frequencies; the switching PIM handles at "
                                 "most 16",
                                 structure.load_groups().size()));
  }
  const Operators ops = make_operators(structure, options);
  return make_fixed<detail::kFixedSizes>(ops, options);
}

}  // namespace pwl
