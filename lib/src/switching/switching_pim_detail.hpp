#pragma once
// Pieces shared by the dense and the banded higher-order PIM (switching_pim.hpp,
// banded_switching_pim.hpp); private to pwl_core.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "event/event_location.hpp"
#include "integrators/fixed_step_count.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/errors.hpp"
#include "pwl/types.hpp"

namespace pwl::switching_detail {

inline constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// The gap functions of one piece of a switching step as polynomials in σ = s/h on [0, 1]:
// e_j(σ) = Σ_r c(j, r) σ^r (mode-signed).
class PolynomialGaps final : public event_detail::ModeGaps {
 public:
  Matrix c;  // m x (R+1)
  Index springs() const override { return c.rows(); }

  void sample(const event_detail::GapSample&, double s, event_detail::GapSample& out) override {
    const Index m = c.rows();
    const Index R = c.cols() - 1;
    out.t = s;
    if (s == 0.0) {
      // Horner's rule below gives c_0, c_1 and 2 c_2 at σ = 0, exactly for finite coefficients
      // (a series that is not finite fails the step's divergence check either way). Every piece
      // starts here, over all springs, so it is a copy.
      out.e = c.col(0);
      if (R >= 1) {
        out.rate = c.col(1);
      } else {
        out.rate.setZero(m);
      }
      if (R >= 2) {
        out.accel = 2.0 * c.col(2);
      } else {
        out.accel.setZero(m);
      }
      return;
    }
    out.e.resize(m);
    out.rate.resize(m);
    out.accel.resize(m);
    // Horner's rule for every spring at once, column by column (contiguous, vectorised): the
    // value, the first and the second derivative.
    out.e = c.col(R);
    out.rate.setZero();
    out.accel.setZero();
    for (Index k = R - 1; k >= 0; --k) {
      out.accel = out.accel * s + 2.0 * out.rate;
      out.rate = out.rate * s + out.e;
      out.e = out.e * s + c.col(k);
    }
  }

  void derivative_bound(const event_detail::GapSample& from, double span, int order, Vector& bound) override {
    const double top = std::max(0.0, from.t + span);
    const Index R = c.cols() - 1;
    bound = Vector::Zero(c.rows());
    double power = 1.0;  // top^(r - order)
    for (Index r = order; r <= R; ++r) {
      double f = power;  // r!/(r-order)! top^(r-order)
      for (int i = 0; i < order; ++i) f *= static_cast<double>(r - i);
      bound += f * c.col(r).cwiseAbs();
      power *= top;
    }
  }

  void sample_spring(const event_detail::GapSample&, double s, Index j, double* value, double* rate) override {
    const Index R = c.cols() - 1;
    double e = c(j, R), r = 0.0;
    for (Index k = R - 1; k >= 0; --k) {
      r = r * s + e;
      e = e * s + c(j, k);
    }
    *value = e;
    *rate = r;
  }

  void spring_derivatives(const event_detail::GapSample& at, Index j, int max_order, double* d) override {
    const Index R = c.cols() - 1;
    for (int q = 0; q <= max_order; ++q) {
      double sum = 0.0, power = 1.0;
      for (Index r = q; r <= R; ++r) {
        double f = power;
        for (int i = 0; i < q; ++i) f *= static_cast<double>(r - i);
        sum += f * c(j, r);
        power *= at.t;
      }
      d[q] = sum;
    }
  }

  double spring_derivative_bound(const event_detail::GapSample& from, double span, int order,
                                 Index j) override {
    const double top = std::max(0.0, from.t + span);
    const Index R = c.cols() - 1;
    double sum = 0.0, power = 1.0;
    for (Index r = order; r <= R; ++r) {
      double f = power;
      for (int i = 0; i < order; ++i) f *= static_cast<double>(r - i);
      sum += f * std::abs(c(j, r));
      power *= top;
    }
    return sum;
  }

  void derivatives(const event_detail::GapSample& at, int max_order, Matrix& d) override {
    const Index R = c.cols() - 1;
    d = Matrix::Zero(c.rows(), max_order + 1);
    for (int q = 0; q <= max_order; ++q) {
      double power = 1.0;  // at.t^(r - q)
      for (Index r = q; r <= R; ++r) {
        double f = power;
        for (int i = 0; i < q; ++i) f *= static_cast<double>(r - i);
        d.col(q) += f * c.col(r);
        power *= at.t;
      }
    }
  }
};

// The r-th derivative of (sin ωt, cos ωt) over ω^r, from S = sin ωt and C = cos ωt: the cycle
// (S, C, -S, -C) for sin, into ds and dc.
inline void harmonic_derivative(int r, double S, double C, double& ds, double& dc) {
  switch (r % 4) {
    case 0: ds = S; dc = C; break;
    case 1: ds = C; dc = -S; break;
    case 2: ds = -S; dc = -C; break;
    default: ds = -C; dc = S; break;
  }
}

// The springs of a set of gap polynomials (PolynomialGaps, σ in [0, 1]) that can reach their
// kink on the piece, with their polynomials, search settings and samples at σ = 0, for a search
// that need not look at the others. Left out: the springs whose mode-signed gap
// e(σ) = Σ c_r σ^r is certainly positive on [0, 1] (e >= c_0 + c_1 σ - S σ² with S = Σ_{r>=2} |c_r|,
// a concave bound positive at both ends, with a margin for the rounding of the evaluation) and
// that the search would examine from σ = 0 on (no kink tolerance, no certified departure). The
// search never examines a spring before its kink could be reached, so leaving these out changes
// what it finds only through its sample spacing, which they could only shorten; a chain whose
// springs switch in one region no longer samples all of them at every sample.
struct CandidateSprings {
  std::vector<Index> springs;  // the springs kept (rows of the whole set), ascending
  std::vector<int> row_of;     // each spring's row here, -1 for a spring left out
  PolynomialGaps poly;
  event_detail::SearchSettings settings;
  event_detail::GapSample start;
  Vector rest_;  // scratch of select()

  // From the polynomials of every spring (row j is spring j), or, with `names`, of some springs
  // of a set of `total` (possibly none): row k of `all` is spring (*names)[k] (ascending), and
  // springs and row_of speak of the whole set.
  void select(const PolynomialGaps& all, const event_detail::SearchSettings& all_settings,
              const std::vector<Index>* names = nullptr, Index total = 0) {
    const Matrix& c = all.c;
    const Index m = c.rows(), R = c.cols() - 1;
    springs.clear();
    row_of.assign(static_cast<std::size_t>(names == nullptr ? m : total), -1);
    const auto name = [&](Index j) { return names == nullptr ? j : (*names)[static_cast<std::size_t>(j)]; };
    // S_j = Σ_{r>=2} |c(j, r)| column by column (contiguous; the same sums in the same order).
    rest_.setZero(m);
    for (Index r = 2; r <= R; ++r) rest_ += c.col(r).cwiseAbs();
    for (Index j = 0; j < m; ++j) {
      const double rest = rest_[j];
      const double c1 = R >= 1 ? c(j, 1) : 0.0;
      // Horner's rounding on [0, 1] is below about 2R ε Σ|c_r|.
      const double margin =
          (8.0 + 2.0 * static_cast<double>(R)) * kEpsilon * (std::abs(c(j, 0)) + std::abs(c1) + rest);
      const bool clear = c(j, 0) > margin && c(j, 0) + c1 - rest > margin &&
                         all_settings.tolerance[j] == 0.0 &&
                         !(all_settings.certified_until[j] > 0.0);
      if (clear) continue;
      row_of[static_cast<std::size_t>(name(j))] = static_cast<int>(rows_.size());
      rows_.push_back(j);
      springs.push_back(name(j));
    }
    const auto count = static_cast<Index>(springs.size());
    poly.c.resize(count, R + 1);
    settings = all_settings;  // spacing and widths
    settings.tolerance.resize(count);
    settings.certified_until.resize(count);
    for (Index k = 0; k < count; ++k) {
      const Index j = rows_[static_cast<std::size_t>(k)];
      poly.c.row(k) = c.row(j);
      settings.tolerance[k] = all_settings.tolerance[j];
      settings.certified_until[k] = all_settings.certified_until[j];
    }
    rows_.clear();
    start = event_detail::GapSample();
    poly.sample(start, 0.0, start);
  }
  // The springs of a search's result, as rows of the whole set, into `out`.
  void springs_of(const event_detail::SearchResult& r, std::vector<Index>& out) const {
    out.clear();
    for (Index k : r.springs) out.push_back(springs[static_cast<std::size_t>(k)]);
  }

 private:
  std::vector<Index> rows_;  // scratch of select(): the kept rows of `all`
};

// The coefficients of the step's force polynomial from the moments Ξ̂_0 .. Ξ̂_{d+1} (Ξ̂_{d+2} with
// the end slope) of polynomial_force_integrals: correction[r] multiplies p_r (with the end slope,
// the predicted slope Σ r p_r folded in, and one more for p_{d+1}), phi multiplies P_{k+1},
// slope the correction of η P'_{k+1}. For the dense operators and for each substructure of the
// banded ones.
struct ForceCoefficients {
  std::vector<Matrix> correction;
  Matrix phi, slope;
};

inline ForceCoefficients force_coefficients(const std::vector<Matrix>& moments, int d, bool end) {
  const auto moment = [&](int r) -> const Matrix& { return moments[static_cast<std::size_t>(r)]; };
  ForceCoefficients c;
  if (!end) {
    // P(σ) = Σ_{r<=d} p_r σ^r + (P_end - Σ p_r) σ^{d+1}.
    c.phi = moment(d + 1);
    for (int r = 0; r <= d; ++r) c.correction.push_back(moment(r) - c.phi);
    c.slope = Matrix::Zero(c.phi.rows(), c.phi.cols());
    return c;
  }
  // P(σ) = Σ_{r<=d} p_r σ^r + α σ^{d+1} + β σ^{d+2} with P(1) = P_end and P'(1) = q_end
  // (η P' at the end): β = q_end - Σ r p_r - (d+1)(P_end - Σ p_r), α = P_end - Σ p_r - β,
  // so with Δ = Ξ̂_{d+2} - Ξ̂_{d+1} the step is Σ_r (Ξ̂_r - Ξ̂_{d+1} + (d+1-r) Δ) p_r
  // + (Ξ̂_{d+1} - (d+1) Δ) P_end + Δ q_end.
  const Matrix delta = moment(d + 2) - moment(d + 1);
  c.phi = moment(d + 1) - (d + 1) * delta;
  for (int r = 0; r <= d; ++r) c.correction.push_back(moment(r) - moment(d + 1) + (d + 1 - r) * delta);
  c.slope = delta;
  // The predicted end slope Σ_{r=1}^{d+1} r p_r enters through slope; fold it into the
  // coefficients of the p_r (and one more for p_{d+1}).
  for (int r = 1; r <= d; ++r) c.correction[static_cast<std::size_t>(r)] += r * c.slope;
  c.correction.push_back((d + 1) * c.slope);
  return c;
}

// The Taylor series of the motion in one mode and the pieces of a switching step, for the dense
// and the banded stepper alike (CRTP: Stepper derives from this and makes it a friend). The two
// differ only in their storage (fixed-size and dense, or sparse) and in a few hooks:
//
//   void gap_product(const Half& x, Force& out);          // out = W^T x
//   void acceleration(const Half& x, const Half& u, const Force& p, Half& acc);
//                                                          // acc = -M⁻¹ (K x + C u + W p)
//   double kink_tolerance(Index j) const;                  // of spring j at the piece start xs_[0]
//   void begin_piece();                                    // before each piece's series
//   void set_mode(Index j, bool on);
//   void end_pieces();                                     // the state from xs_[0], us_[0]
//   void finish_step();
//   void clear_local_records();                            // the record is dropped
//   void replay_local_step(Index k, Matrix& tangent);      // a local_step op of the record
//
// and the data members mode_, signs_, gaps_, stiffnesses_, spring_offset_, loads_ (omega,
// sin_part, cos_part: M⁻¹ times the load), m_, d_, eta_, o_ (SwitchingPimOptions), diagnostics_
// and stats_, with the same meaning in both.
template <class Stepper, class Half, class Force>
class ModeSeries {
 protected:
  Stepper& self() { return static_cast<Stepper&>(*this); }
  const Stepper& self() const { return static_cast<const Stepper&>(*this); }

  // The grid driver of both steppers' advance_to and advance_with_tangent: every step to t_end,
  // and with `tangent` (2n x p, rows [x; x']) the tangent map of each step applied to it
  // (step_with_tangent; tangent_ points to it for the duration). While a record is open, steps
  // without the tangent note what fixes it all the same (step_with_tangent with tangent_ null),
  // so that a plain integration can be replayed as well.
  void advance_steps(double t_end, Matrix* tangent, const StepObserver& observer) {
    Stepper& st = self();
    if (tangent != nullptr && tangent->rows() != 2 * st.n_) {
      throw InputError(fmt::format("tangent has {} rows; the state [x; x'] has {}",
                                   tangent->rows(), 2 * st.n_));
    }
    tangent_ = tangent;
    struct Release {
      Matrix*& tangent;
      ~Release() { tangent = nullptr; }
    } release{tangent_};
    const bool extending = record_open_;
    record_complete_ = false;
    try {
      detail::advance_on_grid(
          t_end, st.time(), st.eta_, observer, st.position_, st.velocity_,
          [this, &st, tangent] {
            if (tangent != nullptr || noting()) {
              st.step_with_tangent();
            } else {
              st.step();
            }
            return st.time();
          },
          [&st] { st.sync(); });
    } catch (...) {
      end_record();
      throw;
    }
    record_complete_ = extending && record_open_;
  }

  // Tangent recording (Integrator::record_tangent, replay_tangent). The record lists what fixes
  // the tangent map of the motion since set_state, in order: the springs' mode changes, the start
  // of each step, each smooth step's linear part and each piece of a switching step (its step h,
  // its series terms R and where it ends, σ). The state's path does not depend on the tangent,
  // so advance_to notes the same entries as advance_with_tangent. Replaying it from the mode at
  // set_state repeats exactly the tangent arithmetic of advance_with_tangent, without the state's
  // series, the search for switches or the LCP. A few entries per step and switch; beyond
  // kRecordLimit entries the record is dropped (no replay) rather than grow without bound.
  struct TangentOp {
    // local_step: a switching step corrected locally (local_switch_correction.hpp), whose
    // record the stepper keeps; `spring` is its index there.
    enum class Kind : unsigned char { mode_on, mode_off, step_start, smooth_step, piece, local_step };
    Kind kind = Kind::step_start;
    int terms = 0;                // piece: R
    Index spring = 0;             // mode_on, mode_off; local_step: the record's index
    double h = 0.0, sigma = 0.0;  // piece
  };
  static constexpr std::size_t kRecordLimit = std::size_t{1} << 22;  // 128 MiB of entries

  void set_recording(bool on) {
    recording_ = on;
    if (!on) end_record();
  }

  // Called by the stepper's set_state once its modes are set.
  void begin_record() {
    end_record();
    if (!recording_) return;
    record_start_mode_ = self().mode_;
    record_open_ = true;
    record_complete_ = true;  // the identity, until a step is taken
  }

  void end_record() {
    record_open_ = false;
    record_complete_ = false;
    record_.clear();
    self().clear_local_records();
  }

  // Appends to an open record while the stepper advances (not while replaying).
  void note(const TangentOp& op) {
    if (!record_open_ || replaying_) return;
    if (record_.size() >= kRecordLimit) {
      end_record();
      record_.shrink_to_fit();
      return;
    }
    record_.push_back(op);
  }
  // True while the stepper records (note() keeps what it is given).
  bool noting() const { return record_open_ && !replaying_ && record_.size() < kRecordLimit; }
  void note_mode(Index j, bool on) {
    TangentOp op;
    op.kind = on ? TangentOp::Kind::mode_on : TangentOp::Kind::mode_off;
    op.spring = j;
    note(op);
  }

  // The recorded tangent map applied to `tangent`; false without a complete record. The stepper
  // provides replay_step_start() (what step_with_tangent notes before a step) and
  // replay_smooth_step() (a smooth step's linear part, as the step applied it).
  bool replay(Matrix& tangent) {
    Stepper& st = self();
    if (!record_complete_) return false;
    if (tangent.rows() != 2 * st.n_) {
      throw InputError(fmt::format("tangent has {} rows; the state [x; x'] has {}",
                                   tangent.rows(), 2 * st.n_));
    }
    const Force end_mode = st.mode_;
    struct Restore {
      ModeSeries& series;
      Stepper& stepper;
      const Force& mode;
      ~Restore() {
        for (Index j = 0; j < stepper.m_; ++j) stepper.set_mode(j, mode[j] > 0.0);
        series.tangent_ = nullptr;
        series.replaying_ = false;
      }
    } restore{*this, st, end_mode};
    replaying_ = true;
    tangent_ = &tangent;
    for (Index j = 0; j < st.m_; ++j) st.set_mode(j, record_start_mode_[j] > 0.0);
    for (const TangentOp& op : record_) {
      switch (op.kind) {
        case TangentOp::Kind::mode_on: st.set_mode(op.spring, true); break;
        case TangentOp::Kind::mode_off: st.set_mode(op.spring, false); break;
        case TangentOp::Kind::step_start: st.replay_step_start(); break;
        case TangentOp::Kind::smooth_step: st.replay_smooth_step(); break;
        case TangentOp::Kind::piece:
          st.begin_piece();
          tangent_piece(op.h, op.terms, op.sigma);
          break;
        case TangentOp::Kind::local_step:
          st.replay_local_step(op.spring, tangent);
          break;
      }
    }
    return true;
  }

  // Sizes the series buffers for `terms` terms, n degrees of freedom and m springs. The first
  // `eager` terms (those every step reads: its force polynomial's degree and the screen's) are
  // allocated now, the others when a series first reaches them (taylor()): a long series is
  // only needed in the pieces of switching steps and rarely runs to the limit, and 41 terms of
  // the whole state would be 1.3 GB at 10^6 masses, zeroed before the first step.
  void size_series(std::size_t terms, Index n, Index m, std::size_t eager) {
    series_n_ = n;
    series_m_ = m;
    allocated_terms_ = 0;
    for (auto* v : {&xs_, &us_}) {
      v->clear();
      v->resize(terms);  // empty (or, for fixed sizes, not yet set): allocate_terms sets them
    }
    for (auto* v : {&ps_, &gw_}) {
      v->clear();
      v->resize(terms);
    }
    allocate_terms(std::min(eager, terms));
    vx_ = Half::Zero(n);
    vu_ = vx_;
    acc_ = vx_;
    tx_ = vx_;
    tu_ = vx_;
    tsx_ = vx_;
    tsu_ = vx_;
    tacc_ = vx_;
    tg_ = Force::Zero(m);
    tp_ = tg_;
  }

  // Scaled Taylor coefficients of the motion in the current mode about time t for a step h, the
  // start in xs_[0] and us_[0]: xs_[r] = x^{(r)} h^r / r!, us_[r] the same for x', ps_[r] =
  // P^{(r)} h^r / r!, gw_[r] = W^T xs_[r]. Computes xs_ and gw_ up to `last`, us_ and ps_ up to
  // last - 1 (us_[last] too when full). When tol > 0, stops early once two consecutive terms are
  // below tol times the largest; returns the index of the last term computed. With first > 0 the
  // terms up to `first` (velocity and force up to first - 1) are those of a call with the same
  // t, h and start that stopped there, and the series continues from them.
  int taylor(double t, double h, int last, double tol, bool full = true, int first = 0) {
    Stepper& st = self();
    allocate_terms(static_cast<std::size_t>(last) + 1);
    double largest = 0.0;
    if (first == 0) {
      st.gap_product(xs_[0], gw_[0]);
      for (std::size_t g = 0; g < st.loads_.size(); ++g) {
        phase_sin_[g] = std::sin(st.loads_[g].omega * t);
        phase_cos_[g] = std::cos(st.loads_[g].omega * t);
        load_scale_[g] = 1.0;
      }
    }
    // The largest entry of the terms so far (the convergence test's scale): only with tol > 0.
    double u_size = 0.0;  // the largest entry of us_[r] for the r at hand (with tol > 0)
    if (tol > 0.0) {
      for (int r = 0; r <= first; ++r) {
        const auto ru = static_cast<std::size_t>(r);
        u_size = us_[ru].cwiseAbs().maxCoeff();
        largest = std::max({largest, xs_[ru].cwiseAbs().maxCoeff(), u_size});
      }
    }
    series_largest_ = largest;
    double previous = largest;
    for (int r = first; r < last; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      ps_[ru] = st.mode_.cwiseProduct(st.stiffnesses_.cwiseProduct(gw_[ru]));
      if (r == 0) ps_[ru] -= st.mode_.cwiseProduct(st.spring_offset_);
      const double f = h / (r + 1);
      xs_[ru + 1] = f * us_[ru];
      st.gap_product(xs_[ru + 1], gw_[ru + 1]);
      if (!full && r + 1 == last) break;  // the last velocity term is not needed
      st.acceleration(xs_[ru], us_[ru], ps_[ru], acc_);
      for (std::size_t g = 0; g < st.loads_.size(); ++g) {
        // d^r/dt^r of sin and cos at ωt, scaled by (ωh)^r / r!.
        double ds = 0.0, dc = 0.0;
        harmonic_derivative(r, phase_sin_[g], phase_cos_[g], ds, dc);
        const double scale = load_scale_[g];
        if (scale != 0.0) acc_ += scale * (ds * st.loads_[g].sin_part + dc * st.loads_[g].cos_part);
        load_scale_[g] = scale * st.loads_[g].omega * h / (r + 1);
      }
      us_[ru + 1] = f * acc_;
      if (tol > 0.0) {
        // max |f u_i| = f max |u_i| exactly: rounding is monotone and symmetric.
        const double x_size = f * u_size;
        u_size = us_[ru + 1].cwiseAbs().maxCoeff();
        const double size = std::max(x_size, u_size);
        largest = std::max(largest, size);
        series_largest_ = largest;
        if (r + 1 >= 4 && size + previous <= tol * largest) return r + 1;
        previous = size;
      }
    }
    return last;
  }

  // Σ_r a_r σ^r for the state, into vx_ and vu_.
  void evaluate_series(int R, double sigma) {
    vx_ = xs_[static_cast<std::size_t>(R)];
    vu_ = us_[static_cast<std::size_t>(R)];
    for (int r = R - 1; r >= 0; --r) {
      vx_ = vx_ * sigma + xs_[static_cast<std::size_t>(r)];
      vu_ = vu_ * sigma + us_[static_cast<std::size_t>(r)];
    }
  }

  // True when some gap polynomial might reach zero on the step. On σ in [0, 1],
  // e(σ) >= e_0 + e_1 σ - S σ² with S the sum of |e_r| for r >= 2; that concave lower bound is
  // positive on [0, 1] when it is positive at both ends.
  bool screen_fails() const {
    for (Index j = 0; j < self().m_; ++j) {
      if (!screen_clears(j)) return true;
    }
    return false;
  }
  // The same bound for spring j alone.
  bool screen_clears(Index j) const {
    const Stepper& st = self();
    const double e0 = st.signs_[j] * (gw_[0][j] - st.gaps_[j]);
    const double e1 = st.signs_[j] * gw_[1][j];
    double rest = 0.0;
    for (int r = 2; r <= st.d_ + 1; ++r) rest += std::abs(gw_[static_cast<std::size_t>(r)][j]);
    return e0 > 0.0 && e0 + e1 - rest > 0.0;
  }

  // The gap polynomial of the coefficients gw_[0..R] (mode-signed) on σ in [0, 1]; settles the
  // springs on their kink at σ = 0. Returns true when a spring must switch at σ = 0 (its first
  // derivative points away from its mode), listed in flip_.
  bool prepare_polynomial(int R) {
    const Stepper& st = self();
    poly_.c.resize(st.m_, R + 1);
    for (int r = 0; r <= R; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      if (r == 0) {
        poly_.c.col(0) = st.signs_.cwiseProduct(gw_[0] - st.gaps_);
      } else {
        poly_.c.col(r) = st.signs_.cwiseProduct(gw_[ru]);
      }
    }
    return settle_kinks(poly_, nullptr, start_, settings_, flip_);
  }

  // The springs of `poly` (row i is spring springs[i], or spring i without a list) that sit on
  // their kink at σ = 0: those whose motion certainly leaves the kink in the mode's direction get
  // a certified_until time (and the kink tolerance where the departure is not yet certain), those
  // whose motion points to the other side are listed in `flips` (global indices); true when there
  // are such. Samples `poly` at 0 into `start` and resets `settings` for a search on [0, 1].
  bool settle_kinks(PolynomialGaps& poly, const Index* springs, event_detail::GapSample& start,
                    event_detail::SearchSettings& settings, std::vector<Index>& flips) {
    const Stepper& st = self();
    const Index count = poly.springs();
    start = event_detail::GapSample();
    poly.sample(start, 0.0, start);
    // The bounds of a polynomial are tight: try the whole piece at once and split only where
    // the envelopes cannot decide.
    settings.nominal_spacing = 1.0;
    settings.max_spacing = 0.0;
    settings.min_width = 64.0 * kEpsilon;
    settings.tolerance = Vector::Zero(count);
    settings.certified_until = Vector::Constant(count, -std::numeric_limits<double>::infinity());
    flips.clear();
    for (Index i = 0; i < count; ++i) {
      const Index j = springs == nullptr ? i : springs[i];
      const double tol = st.kink_tolerance(j);
      if (start.e[i] > tol) continue;
      double until = 0.0;
      const int verdict =
          locator_.certify_departure(poly, start, i, tol, 1.0, settings.min_width, &until);
      if (verdict < 0) {
        flips.push_back(j);
      } else {
        settings.certified_until[i] = until;
        if (verdict == 0) settings.tolerance[i] = tol;
      }
    }
    return !flips.empty();
  }

  // The step redone in pieces: each piece follows the Taylor series of the current mode up to
  // the first located switch, or to the end of the step. On entry xs_[0], us_[0] hold the step's
  // start and the series up to order d_ + 1 is in the buffers; the first piece continues that
  // series instead of starting again (with `fresh`, the buffers hold some other series of the
  // start: it starts again). `method` names the stepper in errors.
  void switching_step(double t0, const char* method, bool fresh = false) {
    Stepper& st = self();
    ++st.diagnostics_.switching_steps;
    double s = 0.0;
    int guard = 0;
    int resume = fresh ? 0 : st.d_;
    while (s < st.eta_) {
      if (++guard > 10000) {
        throw DivergenceError(fmt::format(
            "{}: more than 10000 pieces in the step at t = {}: the springs chatter at their "
            "kinks",
            method, t0));
      }
      double h = st.eta_ - s;
      bool whole = true;
      int R = 0;
      st.begin_piece();
      while (true) {
        R = taylor(t0 + s, h, st.o_.max_series_terms, 0.5 * kEpsilon, true, resume);
        resume = 0;
        if (R < st.o_.max_series_terms) break;
        h *= 0.5;
        whole = false;
        ++st.diagnostics_.halved_pieces;
        if (!(h > 0.0)) {
          throw DivergenceError(fmt::format("{}: the Taylor series did not converge", method));
        }
      }
      ++st.diagnostics_.pieces;
      if (prepare_polynomial(R)) {
        // A spring on its kink whose motion points to the other side: its mode was a guess (a
        // start exactly at the kink) or it only touched; correct it, not counted as a switch,
        // and start the new mode's series from the same point.
        for (Index j : flip_) st.set_mode(j, !(st.mode_[j] > 0.0));
        continue;
      }
      // Long structures search only the springs that can switch in the piece (CandidateSprings);
      // with a few springs, every one.
      const bool screened = st.m_ >= kScreenedSprings;
      if (screened) candidates_.select(poly_, settings_);
      const event_detail::SearchResult& r =
          screened ? locator_.find_first_crossing(candidates_.poly, candidates_.start, 1.0,
                                                  candidates_.settings)
                   : locator_.find_first_crossing(poly_, start_, 1.0, settings_);
      st.diagnostics_.gap_samples += r.samples;
      if (screened) {
        candidates_.springs_of(r, crossing_);
      } else {
        crossing_.assign(r.springs.begin(), r.springs.end());
      }
      const double sigma = r.found ? r.at.t : 1.0;
      evaluate_series(R, sigma);
      if (tangent_ != nullptr) tangent_piece(h, R, sigma);
      if (noting()) {
        TangentOp op;
        op.kind = TangentOp::Kind::piece;
        op.terms = R;
        op.h = h;
        op.sigma = sigma;
        note(op);
      }
      if (r.found) {
        s = r.at.t >= 1.0 && whole ? st.eta_ : s + r.at.t * h;
        for (Index j : crossing_) toggle(j);
      } else {
        s = whole ? st.eta_ : s + h;
      }
      xs_[0].swap(vx_);
      us_[0].swap(vu_);
    }
    st.end_pieces();
    st.finish_step();
  }

  // The tangent map of one piece: the piece's end state is Σ_r a_r σ^r with the a_r of
  // taylor(), affine in the piece's start; its linear part is the same recursion without the
  // loads and the spring offsets K2 Δ (the mode is fixed inside the piece), applied to every
  // column of *tangent_ (rows [x; x']) and summed at the same σ. The R terms of the state's series
  // at least, more while the tangent's own terms are above rounding (a state whose series stops
  // early by accident, at rest, say, must not truncate the tangent's). The dependence of σ on the
  // start (a located switch) adds (f_old - f_new) dt*/dy to the next piece's start, where f_old
  // and f_new are the two modes' vector fields at the switch: they differ by the switching
  // spring's force K2 (w^T x - Δ), zero at the located root up to its tolerance, so that term is
  // left out (no saltation for a continuous vector field).
  void tangent_piece(double h, int R, double sigma) {
    Matrix& Y = *tangent_;
    const Index n = xs_[0].size();
    for (Index c = 0; c < Y.cols(); ++c) {
      tx_ = Y.col(c).head(n);
      tu_ = Y.col(c).tail(n);
      tangent_series(h, R, sigma, [](int, const Half&) {});
      Y.col(c).head(n) = tsx_;
      Y.col(c).tail(n) = tsu_;
    }
  }

  // The series of tangent_piece for one column, started from tx_, tu_ and summed at σ into tsx_,
  // tsu_; on_term(r, x_r) sees the position part of every term, r = 0, 1, ... (the local switch
  // corrections read the switching springs' gaps off them).
  template <class OnTerm>
  void tangent_series(double h, int R, double sigma, OnTerm&& on_term) {
    Stepper& st = self();
    const int limit = std::max(R, st.o_.max_series_terms);
    constexpr double tol = 0.5 * kEpsilon;
    tsx_ = tx_;
    tsu_ = tu_;
    on_term(0, tx_);
    double largest = std::max(tx_.cwiseAbs().maxCoeff(), tu_.cwiseAbs().maxCoeff());
    double previous = largest, power = 1.0;
    for (int r = 0; r < limit; ++r) {
      st.gap_product(tx_, tg_);
      tp_ = st.mode_.cwiseProduct(st.stiffnesses_.cwiseProduct(tg_));
      st.acceleration(tx_, tu_, tp_, tacc_);
      const double f = h / (r + 1);
      tx_ = f * tu_;
      tu_ = f * tacc_;
      on_term(r + 1, tx_);
      power *= sigma;
      tsx_ += power * tx_;
      tsu_ += power * tu_;
      const double size = std::max(tx_.cwiseAbs().maxCoeff(), tu_.cwiseAbs().maxCoeff());
      largest = std::max(largest, size);
      if (r + 1 >= R && r + 1 >= 4 && size + previous <= tol * largest) break;
      previous = size;
    }
  }

  void toggle(Index j) {
    Stepper& st = self();
    st.set_mode(j, !(st.mode_[j] > 0.0));
    ++st.diagnostics_.switches;
    ++st.stats_.kink_events;
  }

  std::vector<Half> xs_, us_;
  std::vector<Force> ps_, gw_;
  Index series_n_ = 0, series_m_ = 0;
  std::size_t allocated_terms_ = 0;  // xs_, us_, ps_, gw_ [0, allocated_terms_) are sized
  // Sizes (zeroed) the terms below `count` that are not yet.
  void allocate_terms(std::size_t count) {
    for (; allocated_terms_ < std::min(count, xs_.size()); ++allocated_terms_) {
      xs_[allocated_terms_] = Half::Zero(series_n_);
      us_[allocated_terms_] = Half::Zero(series_n_);
      ps_[allocated_terms_] = Force::Zero(series_m_);
      gw_[allocated_terms_] = Force::Zero(series_m_);
    }
  }
  // With tol > 0, the largest entry of the terms 0 .. R of taylor()'s last series.
  double series_largest_ = 0.0;
  Half vx_, vu_;  // the state a piece ends in
  Half acc_;      // scratch of taylor()
  // advance_with_tangent: the tangent (2n x p, rows [x; x']) the pieces also map, null otherwise;
  // scratch of tangent_piece().
  Matrix* tangent_ = nullptr;
  Half tx_, tu_, tsx_, tsu_, tacc_;
  Force tg_, tp_;
  double phase_sin_[16] = {}, phase_cos_[16] = {}, load_scale_[16] = {};
  PolynomialGaps poly_;
  event_detail::EventLocator locator_;
  event_detail::GapSample start_;
  event_detail::SearchSettings settings_;
  std::vector<Index> flip_;
  // The springs searched in a piece when there are kScreenedSprings or more, and the springs a
  // search found crossing (rows of the whole set).
  static constexpr Index kScreenedSprings = 64;
  CandidateSprings candidates_;
  std::vector<Index> crossing_;
  // The tangent record (see TangentOp).
  bool recording_ = false, record_open_ = false, record_complete_ = false, replaying_ = false;
  std::vector<TangentOp> record_;
  Force record_start_mode_;
};

}  // namespace pwl::switching_detail
