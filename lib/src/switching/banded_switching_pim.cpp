// The higher-order PIM of switching_pim.hpp with the banded operators of He, Gao & Zhong, Appl.
// Math. Mech. 39(7) (2018) 737-749, §2: the force moments of every substructure assembled into
// banded matrices, sparse products in the Taylor recursion and in the pieces of switching steps.
#include "pwl/integrators/banded_switching_pim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "event/event_location.hpp"
#include "pwl/numerics/banded_matrix.hpp"
#include "pwl/integrators/banded_pim_integrator.hpp"
#include "pwl/integrators/banded_step_operators.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/step_guard.hpp"
#include "integrators/fixed_step_count.hpp"
#include "pwl/numerics/substructure_exponential.hpp"
#include "pwl/numerics/state_checks.hpp"
#include "numerics/row_blocks.hpp"
#include "numerics/serial_products.hpp"
#include "banded/ordered_springs.hpp"
#include "banded/periodic_cut.hpp"
#include "switching/local_gap_screen.hpp"
#include "switching/local_switch_correction.hpp"
#include "switching/switching_pim_detail.hpp"

namespace pwl {

bool BandedSwitchingPimOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  return check_nested(pim.is_valid(why), "pim", why) &&
         check_nested(band.is_valid(why), "band", why) &&
         check_nested(lcp.is_valid(why), "lcp", why);
}

namespace {

using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using switching_detail::kEpsilon;

using switching_detail::ForceCoefficients;
using switching_detail::force_coefficients;

// Row blocks with their substructures, partitioned as the banded exponential's
// (row_blocks.hpp), so that the coefficients come from the same substructures.
using banded_detail::RowBlock;
using banded_detail::partition_rows;

// The force coefficients for unit accelerations at every degree of freedom (G = [0; I]) as banded
// 2n x n matrices on the interleaved state, band q: each row read off the substructure of its
// block, whose moments come from polynomial_force_integrals on the substructure's H.
// Returns correction..., phi, slope in that order.
std::vector<BandedMatrix> banded_force_coefficients(const GapStructure& s, double eta, int d,
                                                    bool end, Index q, Index margin, Index cell,
                                                    const BandedExponentialOptions& o) {
  const Index n = s.dofs();
  const std::vector<RowBlock> blocks = partition_rows(n, margin, cell);
  const std::size_t count = static_cast<std::size_t>(d + 1 + (end ? 1 : 0) + 2);
  std::vector<BandedMatrixBuilder> builders;
  builders.reserve(count);
  for (std::size_t k = 0; k < count; ++k) builders.emplace_back(2 * n, n, 2 * q + 1, o.share_rows);
  std::unordered_map<SubstructureKey, std::shared_ptr<const std::vector<Matrix>>,
                     SubstructureKey::Hasher>
      cache;
  std::vector<double> row(static_cast<std::size_t>(2 * q + 1));
  // The rows of one block, read off its substructure's coefficients.
  const auto set_rows = [&](const RowBlock& block, const std::vector<Matrix>& coefficients) {
    const Index w = block.window_last - block.window_first, first = block.window_first;
    for (Index i = block.begin; i < block.end; ++i) {
      const Index li = i - first;
      const Index lo = std::max<Index>(0, i - q), hi = std::min(n, i + q + 1);
      const Index span = hi - lo, l0 = lo - first;
      for (int a = 0; a < 2; ++a) {
        const Index r = a * w + li;
        for (std::size_t k = 0; k < count; ++k) {
          for (Index j = 0; j < span; ++j) row[static_cast<std::size_t>(j)] = coefficients[k](r, l0 + j);
          builders[k].set_row(2 * i + a, lo, row.data(), span);
        }
      }
    }
  };
  // The coefficients do not depend on the loads: substructures repeat with the cells.
  const banded_detail::CellRepeats repeats(s, cell, {});
  const auto back = static_cast<std::size_t>(repeats.shift() / std::max<Index>(cell, 1));
  // The coefficients of the last `back` blocks (block b at b % back), so that a structure whose
  // cells all differ keeps no more than the cache's 64 sets alive.
  std::vector<std::shared_ptr<const std::vector<Matrix>>> recent(std::max<std::size_t>(back, 1));
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const RowBlock& block = blocks[b];
    auto& slot = recent[b % recent.size()];  // held block b - back until now
    if (back > 0 && b >= back && slot &&
        banded_detail::repeats_block(blocks[b - back], block, repeats)) {
      set_rows(block, *slot);  // that block's substructure, `back` cells on
      continue;
    }
    SubstructureKey key(s, block.window_first, block.window_last);
    auto it = cache.find(key);
    if (it == cache.end()) {
      // Keep the cache small for structures whose cells all differ.
      if (cache.size() >= 64) cache.clear();
      const Index w = block.window_last - block.window_first;
      const Matrix H = substructure_state_matrix(s, block.window_first, block.window_last);
      Matrix G = Matrix::Zero(2 * w, w);
      G.bottomRows(w).setIdentity();
      const auto serial = numerics_detail::SerialProducts::for_rows(2 * w);
      const PolynomialForceIntegrals pfi =
          polynomial_force_integrals(H, eta, G, d + (end ? 2 : 1), o.exponential);
      ForceCoefficients c = force_coefficients(pfi.moments, d, end);
      auto all = std::make_shared<std::vector<Matrix>>(std::move(c.correction));
      all->push_back(std::move(c.phi));
      all->push_back(std::move(c.slope));
      it = cache.emplace(std::move(key), std::move(all)).first;
    }
    slot = it->second;
    set_rows(block, *slot);
  }
  std::vector<BandedMatrix> out;
  out.reserve(count);
  for (BandedMatrixBuilder& b : builders) out.push_back(b.build());
  return out;
}

// The step's banded operators of one structure (the members of BandedStepper below).
struct StepOperatorSet {
  BandTruncation truncation;
  BandedMatrix transition;
  std::vector<HarmonicResponse> harmonics;
  std::vector<BandedMatrix> correction, correction_columns;
  BandedMatrix phi, phi_columns, slope, slope_columns;
  BandedMatrix lcp;  // I - K2 W^T Φ_x (not yet checked to be a P-matrix)
};

// Row by row from the substructures: T and the harmonic responses from the banded exponential,
// the force coefficients from the same substructures, their products with -M⁻¹W, and the LCP.
StepOperatorSet build_step_operators(const GapStructure& s, double eta, int d, bool end,
                                     const BandedExponentialOptions& band) {
  StepOperatorSet out;
  BandedExponential e = make_banded_exponential(s, eta, band);
  out.truncation = e.truncation;
  out.transition = std::move(e.transition);
  out.harmonics = std::move(e.harmonics);
  if (s.spring_count() == 0) return out;
  const banded_detail::OrderedSprings springs = banded_detail::ordered_springs(s);
  const SparseMatrix force_part = banded_detail::spring_accelerations(s, springs.directions);
  const std::vector<BandedMatrix> unit =
      banded_force_coefficients(s, eta, d, end, out.truncation.band, out.truncation.margin,
                                out.truncation.cell_dofs, band);
  const std::size_t corrections = unit.size() - 2;
  for (std::size_t r = 0; r < corrections; ++r) {
    out.correction.push_back(multiply(unit[r], force_part));
    out.correction_columns.push_back(transpose(out.correction.back()));
  }
  out.phi = multiply(unit[corrections], force_part);
  out.phi_columns = transpose(out.phi);
  out.slope = multiply(unit[corrections + 1], force_part);
  out.slope_columns = transpose(out.slope);
  const SparseMatrix minus_spring_rows =
      banded_detail::scaled_rows(SparseMatrix(springs.directions.transpose()), -springs.stiffnesses);
  out.lcp = add_diagonal(multiply(minus_spring_rows, select_rows(out.phi, 0, 2)),
                         Vector::Ones(s.spring_count()));
  return out;
}

// The operators of a long chain from those of the short chain of `cut` (periodic_cut.hpp).
StepOperatorSet repeat_period(const StepOperatorSet& o, const banded_detail::PeriodicCut& cut,
                              const AxisRepeat& springs) {
  const AxisRepeat state = banded_detail::state_axis(cut);
  StepOperatorSet out;
  out.truncation = banded_detail::laid_out_truncation(o.truncation, cut);
  out.transition = repeat_period(o.transition, state, state);
  out.harmonics = banded_detail::repeat_period(o.harmonics, state);
  if (o.lcp.rows() == 0) return out;  // no springs
  for (std::size_t r = 0; r < o.correction.size(); ++r) {
    out.correction.push_back(repeat_period(o.correction[r], state, springs));
    out.correction_columns.push_back(repeat_period(o.correction_columns[r], springs, state));
  }
  out.phi = repeat_period(o.phi, state, springs);
  out.phi_columns = repeat_period(o.phi_columns, springs, state);
  out.slope = repeat_period(o.slope, state, springs);
  out.slope_columns = repeat_period(o.slope_columns, springs, state);
  out.lcp = repeat_period(o.lcp, springs, springs);
  return out;
}

struct LoadTerm {
  double omega;
  Vector sin_part;  // M⁻¹ times the load's sin part
  Vector cos_part;
};

class BandedStepper final : public SwitchingPim,
                            private switching_detail::ModeSeries<BandedStepper, Vector, Vector>,
                            private switching_detail::LocalSwitchCorrection<BandedStepper>,
                            private switching_detail::LocalGapScreen<BandedStepper> {
  friend switching_detail::ModeSeries<BandedStepper, Vector, Vector>;
  friend switching_detail::LocalSwitchCorrection<BandedStepper>;
  friend switching_detail::LocalGapScreen<BandedStepper>;
  using TangentOp = switching_detail::ModeSeries<BandedStepper, Vector, Vector>::TangentOp;
  using RowSparseMatrix = RowSparse;
  static constexpr const char* kMethodName = "pim-switching-banded";

 public:
  BandedStepper(const GapStructure& s, const BandedSwitchingPimOptions& options)
      : o_(options.pim), n_(s.dofs()), m_(s.spring_count()), d_(options.pim.force_degree),
        eta_(options.pim.step), end_derivative_(options.pim.end_derivative),
        correction_mode_(options.switch_correction), free_windows_(options.windowed_free_motion),
        solver_(options.lcp) {
    // Sparse parts of the equation of motion, springs by position along the structure.
    const Vector inverse_mass = s.mass.diagonal().cwiseInverse();
    banded_detail::OrderedSprings springs = banded_detail::ordered_springs(s);
    const SparseMatrix& W = springs.directions;
    gaps_ = std::move(springs.gaps);
    stiffnesses_ = std::move(springs.stiffnesses);
    stiffness_part_ = RowSparse(banded_detail::scaled_rows(s.stiffness, -inverse_mass));
    damping_part_ = RowSparse(banded_detail::scaled_rows(s.damping, -inverse_mass));
    const SparseMatrix force_part = banded_detail::spring_accelerations(s, W);
    force_part_ = RowSparse(force_part);
    gap_rows_ = RowSparse(SparseMatrix(W.transpose()));
    spring_rows_ = RowSparse(stiffnesses_.asDiagonal() * gap_rows_);
    spring_offset_ = stiffnesses_.cwiseProduct(gaps_);
    // The same operators as bands for the whole-state products of every step (the Taylor
    // recursion, the gaps, the LCP's right-hand side): a chain's rows repeat, so these stream the
    // vectors; the sparse forms above serve the local corrections' row-by-row sums.
    stiffness_band_ = BandedMatrix::from_sparse_nonzeros(SparseMatrix(stiffness_part_));
    damping_band_ = BandedMatrix::from_sparse_nonzeros(SparseMatrix(damping_part_));
    force_band_ = BandedMatrix::from_sparse_nonzeros(force_part);
    gap_band_ = BandedMatrix::from_sparse_nonzeros(W.transpose());
    spring_band_ = BandedMatrix::from_sparse_nonzeros(SparseMatrix(spring_rows_));
    // The reach of one Taylor term: the farthest two rows that K, C or a spring couple.
    for (const RowSparse* part : {&stiffness_part_, &damping_part_, &gap_rows_}) {
      for (Index i = 0; i < part->outerSize(); ++i) {
        Index lo = i, hi = i;
        for (RowSparse::InnerIterator it(*part, i); it; ++it) {
          lo = std::min(lo, it.col());
          hi = std::max(hi, it.col());
        }
        // gap rows: a spring's two ends; the others: a row and its columns.
        reach_ = std::max(reach_, part == &gap_rows_ ? hi - lo : std::max(i - lo, hi - i));
      }
    }
    reach_ = std::max<Index>(reach_, 1);
    abs_row_sums_.resize(m_);
    for (Index j = 0; j < m_; ++j) {
      double sum = 0.0;
      for (RowSparse::InnerIterator it(gap_rows_, j); it; ++it) sum += std::abs(it.value());
      abs_row_sums_[j] = sum;
    }
    for (const LoadGroup& g : s.load_groups()) {
      loads_.push_back({g.omega, g.sin_part.cwiseProduct(inverse_mass),
                        g.cos_part.cwiseProduct(inverse_mass)});
    }

    // η ω_max as the dense stepper and the step guard take it (contact_frequency: Gershgorin's
    // bound beyond kDenseFrequencyDofs, O(nonzeros)).
    diagnostics_.step_argument = eta_ * contact_frequency(s).omega_max;
    if ((d_ > 0 || end_derivative_) && diagnostics_.step_argument > o_.max_step_argument) {
      throw InputError(fmt::format(
          "pim.step = {}: η ω_max = {:.3g} exceeds max_step_argument = {} (the contact is too "
          "stiff for the force derivatives at this step); use a step below {:.3g}, or "
          "force_degree = 0 with end_derivative = false",
          eta_, diagnostics_.step_argument, o_.max_step_argument,
          eta_ * o_.max_step_argument / diagnostics_.step_argument));
    }

    // T, the harmonic responses and the band from the banded exponential; the force
    // coefficients from the same substructures; from the period where the chain's middle
    // repeats, row by row otherwise.
    BandedExponentialOptions band = options.band;
    if (band.cell_dofs == 0) band.cell_dofs = detect_cell_size(s);
    std::optional<StepOperatorSet> from_period = banded_detail::build_from_period<StepOperatorSet>(
        s, band,
        [&](const GapStructure& short_chain) {
          return build_step_operators(short_chain, eta_, d_, end_derivative_, band);
        },
        [](const StepOperatorSet& built, const banded_detail::PeriodicCut& cut,
           const AxisRepeat& springs) { return repeat_period(built, cut, springs); });
    diagnostics_.from_period = from_period.has_value();
    StepOperatorSet ops = from_period ? std::move(*from_period)
                                      : build_step_operators(s, eta_, d_, end_derivative_, band);
    truncation_ = ops.truncation;
    transition_ = std::move(ops.transition);
    harmonics_ = std::move(ops.harmonics);
    if (m_ > 0) {
      correction_ = std::move(ops.correction);
      correction_columns_ = std::move(ops.correction_columns);
      phi_ = std::move(ops.phi);
      phi_columns_ = std::move(ops.phi_columns);
      slope_ = std::move(ops.slope);
      slope_columns_ = std::move(ops.slope_columns);
      std::string why;
      if (!is_p_matrix(ops.lcp, &why)) {
        throw InputError(fmt::format("pim.step = {}: the step's LCP matrix is not a P-matrix "
                                     "({}); use a smaller step",
                                     eta_, why));
      }
      solver_.set_matrix(ops.lcp);
      lcp_ = std::move(ops.lcp);
      lcp_lower_ = lcp_.lower_bandwidth();
      lcp_upper_ = lcp_.upper_bandwidth();
    }

    const int terms = std::max(o_.max_series_terms, d_ + 2) + 1;
    size_series(static_cast<std::size_t>(terms), n_, m_, static_cast<std::size_t>(d_ + 4));
    size_local(m_);
    mode_ = Vector::Zero(m_);
    signs_ = Vector::Constant(m_, -1.0);
    state_ = Vector::Zero(2 * n_);
    bar_ = state_;
    half_ = Vector::Zero(n_);
    z_ = Vector::Zero(m_);
    q_ = z_;
    slope_guess_ = z_;
    position_ = Vector::Zero(n_);
    velocity_ = position_;
  }

  Method method() const override { return Method::pim_switching_banded; }
  std::string name() const override {
    return fmt::format("pim-switching-banded (order {}{}, step {:.6g}, band {})",
                       d_ + (end_derivative_ ? 3 : 2),
                       o_.locate_switches ? ", located switches" : "", eta_, truncation_.band);
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
    state_ = interleave_state(x, v);
    // Touching where the gap is closed; a spring exactly at its kink starts slack and the first
    // step settles it from its derivatives.
    const Vector g = gap_rows_ * x - gaps_;
    for (Index j = 0; j < m_; ++j) set_mode(j, g[j] > 0.0);
    x_scale_ = x.cwiseAbs().maxCoeff();
    lcp_synced_ = false;
    sync();
    this->begin_record();
  }

  void advance_to(double t_end, const StepObserver& observer) override {
    this->advance_steps(t_end, nullptr, observer);
  }

  // advance_to, and the tangent map of every step applied to `tangent` (see
  // banded_switching_pim.hpp): column by column, O(n q) per column and step.
  void advance_with_tangent(double t_end, Matrix& tangent, const StepObserver& observer) override {
    this->advance_steps(t_end, &tangent, observer);
  }

  // Tangent replay (integrator.hpp): the record of ModeSeries, with the smooth steps' linear part
  // applied by tangent_smooth_step() as in step_with_tangent().
  bool can_record_tangent() const override { return true; }
  void record_tangent(bool on) override { this->set_recording(on); }
  bool replay_tangent(Matrix& tangent) override { return this->replay(tangent); }

 private:
  void set_mode(Index j, bool on) {
    if ((mode_[j] > 0.0) != on) this->note_mode(j, on);
    mode_[j] = on ? 1.0 : 0.0;
    signs_[j] = on ? 1.0 : -1.0;
  }

  void sync() { deinterleave_state(state_, position_, velocity_); }

  // The springs whose force can be non-zero in the current mode.
  void collect_acting() {
    acting_.clear();
    for (Index j = 0; j < m_; ++j) {
      if (mode_[j] > 0.0) acting_.push_back(static_cast<int>(j));
    }
  }

  // y += A p for p zero outside acting_: by the rows of A when many springs act, by the columns
  // of the acting ones otherwise (O(contacts · q)).
  void add_forces(const BandedMatrix& A, const BandedMatrix& columns, const Vector& p,
                  Vector& y) const {
    add_forces(A, columns, p, y, acting_);
  }
  // The same for p zero outside `acting`.
  void add_forces(const BandedMatrix& A, const BandedMatrix& columns, const Vector& p, Vector& y,
                  const std::vector<int>& acting) const {
    if (acting.empty()) return;
    if (4 * static_cast<Index>(acting.size()) > m_) {
      A.multiply_add(p.data(), y.data());
    } else {
      columns.transpose_multiply_add(p.data(), acting.data(), static_cast<Index>(acting.size()),
                                     y.data());
    }
  }

  // One step and its tangent map. A switching step maps the tangent piece by piece as it goes
  // (ModeSeries::tangent_piece); a smooth step is affine in the start state for the mode it
  // starts in and the LCP's active set, and tangent_smooth_step() applies its linear part after it.
  // Without a tangent (a plain advance while recording) the step only notes what fixes it.
  void step_with_tangent() {
    if (tangent_ != nullptr) replay_step_start();
    this->note({TangentOp::Kind::step_start});
    const long before = diagnostics_.switching_steps;
    step();
    if (diagnostics_.switching_steps == before) {
      if (tangent_ != nullptr) tangent_smooth_step();
      this->note({TangentOp::Kind::smooth_step});
    }
  }

  // The hooks of ModeSeries::replay: the mode a step starts in, and a smooth step's linear part
  // with the touching springs of the mode it ends in (what step() left in acting_).
  void replay_step_start() {
    start_mode_ = mode_;
    start_acting_.clear();
    for (Index j = 0; j < m_; ++j) {
      if (mode_[j] > 0.0) start_acting_.push_back(static_cast<int>(j));
    }
  }
  void replay_smooth_step() {
    collect_acting();
    tangent_smooth_step();
  }

  // The linear part of a smooth step applied to each tangent column: the step's formula with the
  // loads and the spring offsets left out, the force derivatives p_r of the start mode, and the
  // LCP replaced by the linear solve on its active set A (the derivative of the LCP's solution
  // where A is locally constant: dz_A = -M_AA⁻¹ dq_A, dz = 0 elsewhere): one banded product
  // with T, d + 1 sparse recursion terms and the forces of the touching springs, as the step.
  //
  // The recursion only feeds the forces p_r of the springs touching at the start. Each term
  // couples rows at most reach_ apart, so when few springs touch, the terms are computed on the
  // rows their p_r reach back to (force_window_), with the sparse rows as the local switch
  // corrections use them: O(touching springs · d² reach) per column instead of O(n d). None
  // touching: no recursion at all.
  void tangent_smooth_step() {
    Matrix& Y = *tangent_;
    const int last = d_ + (end_derivative_ ? 1 : 0);  // the last p_r the step uses
    if (m_ > 0 && !acting_.empty()) factor_active_set(acting_);
    const bool windowed = !start_acting_.empty() && prepare_force_window(last);
    for (Index c = 0; c < Y.cols(); ++c) {
      t_x_ = Y.col(c).head(n_);
      t_u_ = Y.col(c).tail(n_);
      t_y_.resize(2 * n_);
      t_bar_.resize(2 * n_);
      for (Index i = 0; i < n_; ++i) {
        t_y_[2 * i] = t_x_[i];
        t_y_[2 * i + 1] = t_u_[i];
      }
      transition_.multiply(t_y_.data(), t_bar_.data());
      if (end_derivative_) t_slope_.setZero(m_);
      if (windowed) windowed_force_recursion(last);
      for (int r = 0; r <= last && !start_acting_.empty() && !windowed; ++r) {
        band_product(gap_band_, t_x_, t_g_);
        t_p_ = start_mode_.cwiseProduct(stiffnesses_.cwiseProduct(t_g_));
        const auto ru = static_cast<std::size_t>(r);
        add_forces(correction_[ru], correction_columns_[ru], t_p_, t_bar_, start_acting_);
        if (end_derivative_ && r >= 1) t_slope_ += static_cast<double>(r) * t_p_;
        if (r == last) break;
        const double f = eta_ / (r + 1);
        if (r < d_) {
          accelerate(t_x_, t_u_, t_p_, !start_acting_.empty(), t_acc_);
        }
        t_x_ = f * t_u_;
        if (r < d_) t_u_ = f * t_acc_;
      }
      if (m_ > 0 && !acting_.empty()) {
        // -dq = K2 W^T dbar_x; dz on the active set.
        for (Index i = 0; i < n_; ++i) t_half_[i] = t_bar_[2 * i];
        band_product(spring_band_, t_half_, t_g_);
        solve_active_set(acting_, t_g_, t_z_);
        add_forces(phi_, phi_columns_, t_z_, t_bar_);
        if (end_derivative_ && o_.locate_switches) {
          // The end-slope correction, with the slope of the new state (same mode at both ends).
          for (Index i = 0; i < n_; ++i) t_half_[i] = t_bar_[2 * i + 1];
          band_product(gap_band_, t_half_, t_g_);
          t_slope_ = eta_ * mode_.cwiseProduct(stiffnesses_.cwiseProduct(t_g_)) - t_slope_;
          add_forces(slope_, slope_columns_, t_slope_, t_bar_);
        }
      }
      for (Index i = 0; i < n_; ++i) {
        Y(i, c) = t_bar_[2 * i];
        Y(n_ + i, c) = t_bar_[2 * i + 1];
      }
    }
  }

  // The rows of the windowed recursion of tangent_smooth_step for the springs touching at the
  // start, their masses R: force_window_[r] holds the rows of the r-th terms. p_r needs x_r on R;
  // x_r = f u_{r-1} needs u_{r-1} on R, and u_{r-1} = f a_{r-2} needs the terms r - 2 on R
  // widened by reach_. So the terms r < last live on R widened by reach_ (last - 1 - r) and the
  // last on R. False (use the whole state) when the window covers half the rows or more.
  bool prepare_force_window(int last) {
    switching_detail::RowRanges masses;
    for (int j : start_acting_) {
      for (RowSparse::InnerIterator it(gap_rows_, j); it; ++it) masses.add(it.col(), it.col() + 1);
    }
    masses.normalize();
    force_window_.resize(static_cast<std::size_t>(last) + 1);
    for (int r = 1; r <= last; ++r) {
      force_window_[static_cast<std::size_t>(r)].widen_from(
          masses, reach_ * std::max(0, last - 1 - r), n_);
    }
    if (last >= 1 && 2 * force_window_[1].rows() >= n_) return false;
    for (Vector* v : {&w_x_[0], &w_x_[1], &w_u_[0], &w_u_[1]}) {
      if (v->size() != n_) v->setZero(n_);
    }
    t_p_.setZero(m_);
    return true;
  }

  // The force recursion of tangent_smooth_step on force_window_, from t_x_, t_u_ (the column's
  // start), into t_bar_ and t_slope_; p_r is t_p_ on the touching springs (zero elsewhere, as
  // start_mode_ makes it in the whole-state form).
  void windowed_force_recursion(int last) {
    const Vector* x = &t_x_;
    const Vector* u = &t_u_;
    for (int r = 0; r <= last; ++r) {
      for (int j : start_acting_) t_p_[j] = stiffnesses_[j] * spring_stretch(j, *x);
      const auto ru = static_cast<std::size_t>(r);
      add_forces(correction_[ru], correction_columns_[ru], t_p_, t_bar_, start_acting_);
      if (end_derivative_ && r >= 1) {
        for (int j : start_acting_) t_slope_[j] += static_cast<double>(r) * t_p_[j];
      }
      if (r == last) break;
      const double f = eta_ / (r + 1);
      Vector& x1 = w_x_[ru & 1];
      Vector& u1 = w_u_[ru & 1];
      const bool accelerate_u = r < d_;
      force_window_[ru + 1].for_each_row([&](Index i) {
        x1[i] = f * (*u)[i];
        if (accelerate_u) u1[i] = f * row_acceleration(i, *x, *u, [&](Index j) { return t_p_[j]; });
      });
      x = &x1;
      u = &u1;
    }
    for (int j : start_acting_) t_p_[j] = 0.0;
  }

  // The band LU (no pivoting: M is a P-matrix, so every leading principal minor of M_AA is
  // positive) of M_AA for the ascending index set A, kept in lu_ with lower + upper + 1 entries
  // per row (row k holds columns k - lower .. k + upper of M_AA, L below the diagonal with a unit
  // diagonal, U from it). M_AA is banded with M's bandwidths. The factors of the previous set are
  // kept: row k depends on the rows of A up to k + upper only, so a new set is refactorised from
  // its first index that differs, less the upper bandwidth.
  void factor_active_set(const std::vector<int>& A) {
    const auto a = static_cast<Index>(A.size());
    const Index l = lcp_lower_, u = lcp_upper_, w = l + u + 1;
    const Index common = std::min<Index>(a, static_cast<Index>(lu_set_.size()));
    Index same = 0;
    while (same < common && lu_set_[static_cast<std::size_t>(same)] == A[static_cast<std::size_t>(same)]) ++same;
    if (same == a && static_cast<Index>(lu_set_.size()) == a) return;
    lu_.resize(static_cast<std::size_t>(a * w));
    for (Index k = std::max<Index>(0, same - u); k < a; ++k) {
      double* row = lu_.data() + k * w;  // entry (k, c) at row[c - k + l]
      const Index ik = A[static_cast<std::size_t>(k)];
      for (Index c = k - l; c <= k + u; ++c) {
        row[c - k + l] = c >= 0 && c < a ? lcp_.coeff(ik, A[static_cast<std::size_t>(c)]) : 0.0;
      }
      for (Index i = std::max<Index>(0, k - l); i < k; ++i) {
        const double* ui = lu_.data() + i * w;  // U(i, c) at ui[c - i + l]
        const double factor = row[i - k + l] / ui[l];
        row[i - k + l] = factor;
        if (factor == 0.0) continue;
        const Index top = std::min(i + u, a - 1);
        for (Index c = i + 1; c <= top; ++c) row[c - k + l] -= factor * ui[c - i + l];
      }
      if (!(row[l] > 0.0) || !std::isfinite(row[l])) {
        lu_set_.clear();
        throw DivergenceError(fmt::format(
            "{}: the tangent map's active-set matrix has pivot {} (the LCP matrix is not a "
            "P-matrix)",
            kMethodName, row[l]));
      }
    }
    lu_set_ = A;
  }

  // dz = 0 outside A, dz_A = M_AA⁻¹ (-dq_A) with the factors of factor_active_set(A), for
  // minus_dq = -dq.
  void solve_active_set(const std::vector<int>& A, const Vector& minus_dq, Vector& dz) {
    const auto a = static_cast<Index>(A.size());
    const Index l = lcp_lower_, u = lcp_upper_, w = l + u + 1;
    t_rhs_.resize(static_cast<std::size_t>(a));
    for (Index k = 0; k < a; ++k) {
      const double* row = lu_.data() + k * w;
      double y = minus_dq[A[static_cast<std::size_t>(k)]];
      for (Index i = std::max<Index>(0, k - l); i < k; ++i) y -= row[i - k + l] * t_rhs_[static_cast<std::size_t>(i)];
      t_rhs_[static_cast<std::size_t>(k)] = y;
    }
    for (Index k = a - 1; k >= 0; --k) {
      const double* row = lu_.data() + k * w;
      double y = t_rhs_[static_cast<std::size_t>(k)];
      const Index top = std::min(k + u, a - 1);
      for (Index c = k + 1; c <= top; ++c) y -= row[c - k + l] * t_rhs_[static_cast<std::size_t>(c)];
      t_rhs_[static_cast<std::size_t>(k)] = y / row[l];
    }
    dz.setZero(m_);
    for (Index k = 0; k < a; ++k) dz[A[static_cast<std::size_t>(k)]] = t_rhs_[static_cast<std::size_t>(k)];
  }

  // The hooks of ModeSeries (switching_pim_detail.hpp), which holds the Taylor recursion and the
  // pieces of switching steps, here with banded products; xs_[0] and us_[0] hold the start.
  void gap_product(const Vector& x, Vector& out) const { band_product(gap_band_, x, out); }
  void acceleration(const Vector& x, const Vector& u, const Vector& p, Vector& acc) const {
    accelerate(x, u, p, !acting_.empty(), acc);
  }
  // acc = -M⁻¹ (K x + C u), plus -M⁻¹ W p when springs act.
  void accelerate(const Vector& x, const Vector& u, const Vector& p, bool forces,
                  Vector& acc) const {
    band_product(stiffness_band_, x, acc);
    damping_band_.multiply_add(u.data(), acc.data());
    if (forces) force_band_.multiply_add(p.data(), acc.data());
  }
  // The rows [lo, hi) spring j's gap reads (empty for a spring without rows).
  std::pair<Index, Index> spring_span(Index j) const {
    Index lo = n_, hi = 0;
    for (RowSparse::InnerIterator it(gap_rows_, j); it; ++it) {
      lo = std::min(lo, it.col());
      hi = std::max(hi, it.col() + 1);
    }
    return {lo, hi};
  }
  // (W^T x)_j: spring j's stretch in the displacement x, from its sparse row. x is read by row
  // index (a whole-state Vector, or the local corrections' terms).
  template <class Rows>
  double spring_stretch(Index j, const Rows& x) const {
    double g = 0.0;
    for (RowSparse::InnerIterator it(gap_rows_, j); it; ++it) g += it.value() * x[it.col()];
    return g;
  }
  // Row i of -M⁻¹ (K x + C u + W p) from the sparse rows, p_j = force_of(j): the series on rows
  // that are not windows (the local switch corrections' δ, the smooth steps' tangent recursion)
  // row by row; x and u as for spring_stretch.
  template <class Rows, class ForceOf>
  double row_acceleration(Index i, const Rows& x, const Rows& u, ForceOf&& force_of) const {
    double acc = 0.0;
    for (RowSparse::InnerIterator it(stiffness_part_, i); it; ++it) acc += it.value() * x[it.col()];
    for (RowSparse::InnerIterator it(damping_part_, i); it; ++it) acc += it.value() * u[it.col()];
    for (RowSparse::InnerIterator it(force_part_, i); it; ++it) acc += it.value() * force_of(it.col());
    return acc;
  }
  // out = A x (out resized; it must not be x).
  static void band_product(const BandedMatrix& A, const Vector& x, Vector& out) {
    out.resize(A.rows());
    A.multiply(x.data(), out.data());
  }
  double kink_tolerance(Index j) const {
    double reach = 0.0;
    for (RowSparse::InnerIterator it(gap_rows_, j); it; ++it) {
      reach += std::abs(it.value()) * std::abs(xs_[0][it.col()]);
    }
    return 64.0 * kEpsilon * (std::abs(gaps_[j]) + reach + abs_row_sums_[j] * x_scale_);
  }
  void begin_piece() { collect_acting(); }
  // The scaled Taylor terms of the motion about time t for the step η, from the start in
  // xs_[0], us_[0], in the current mode or, with `free`, with every spring open, on the rows of
  // `windows` only, with the whole state's banded stencils restricted to them. The r-th term
  // couples rows at most r · reach apart (K, C and the springs' two ends), so on a window it is
  // exactly the whole state's term on the rows at least r · reach from an edge of the window
  // that is not an end of the structure (window_exact_rows); each term is computed there only,
  // from the exact rows of the term before. (A touching spring's force is read only by rows next
  // to its own, so it is exact where it is read.) After each term r, record(r, x_r): x_r
  // whole-size, exact on the windows' exact rows of term r. Stops once two consecutive
  // terms are below ε/2 of the largest entry seen (at least `scale`; the result in *largest),
  // measured on the exact rows, not before 4 terms: a stopping rule of the same kind as the
  // whole state's (ModeSeries::taylor), not a bound. Returns the last term's index, or -1 when K
  // terms do not get there. O(window rows) per term, whatever n. The finite reach of each term
  // is what makes banded exponentials of chains possible in the first place (He, Gao & Zhong,
  // Appl. Math. Mech. 39(7) (2018) 737-749).
  template <class Record>
  int window_series(double t, const switching_detail::RowRanges& windows, int K, double scale,
                    bool free, double* largest, Record&& record) {
    for (Vector* v : {&free_x_[0], &free_x_[1], &free_u_[0], &free_u_[1], &free_acc_}) {
      if (v->size() != n_) v->setZero(n_);
    }
    if (free_force_.size() != m_) free_force_.setZero(m_);
    // The force band reads every spring attached to a row: the entries of the springs that
    // touched in the last call go back to zero.
    for (int j : force_set_) free_force_[j] = 0.0;
    force_set_.clear();
    const bool forces = !free && !acting_.empty();
    if (forces) force_set_ = acting_;
    const std::size_t groups = loads_.size();
    free_sin_.resize(groups);
    free_cos_.resize(groups);
    free_scale_.resize(groups);
    for (std::size_t g = 0; g < groups; ++g) {
      free_sin_[g] = std::sin(loads_[g].omega * t);
      free_cos_[g] = std::cos(loads_[g].omega * t);
      free_scale_[g] = 1.0;
    }
    const auto& ranges = windows.ranges();
    const Vector* x = &xs_[0];
    const Vector* u = &us_[0];
    record(0, *x);
    double size = 0.0;
    for (const switching_detail::RowRanges::Range& range : ranges) {
      for (Index i = range.first; i < range.second; ++i) {
        size = std::max({size, std::abs((*x)[i]), std::abs((*u)[i])});
      }
    }
    double big = std::max(scale, size), previous = size;
    for (int r = 0; r < K; ++r) {
      const double f = eta_ / (r + 1);
      Vector& x1 = free_x_[static_cast<std::size_t>(r % 2)];
      Vector& u1 = free_u_[static_cast<std::size_t>(r % 2)];
      size = 0.0;
      if (forces) {
        // The touching springs' forces from term r (the offset in the first); read only where
        // exact (above).
        for (int j : acting_) {
          const double force = stiffnesses_[j] * spring_stretch(j, *x);
          free_force_[j] = r == 0 ? force - spring_offset_[j] : force;
        }
      }
      for (const switching_detail::RowRanges::Range& range : ranges) {
        const auto [a, b] = window_exact_rows(range, r + 1);
        stiffness_band_.multiply(x->data(), free_acc_.data(), a, b);
        damping_band_.multiply_add(u->data(), free_acc_.data(), a, b);
        if (forces) force_band_.multiply_add(free_force_.data(), free_acc_.data(), a, b);
        for (std::size_t g = 0; g < groups; ++g) {
          // d^r/dt^r of sin and cos at ωt, scaled by (ωη)^r / r!.
          double ds = 0.0, dc = 0.0;
          switching_detail::harmonic_derivative(r, free_sin_[g], free_cos_[g], ds, dc);
          const double scale_g = free_scale_[g];
          if (scale_g == 0.0) continue;
          for (Index i = a; i < b; ++i) {
            free_acc_[i] += scale_g * (ds * loads_[g].sin_part[i] + dc * loads_[g].cos_part[i]);
          }
        }
        for (Index i = a; i < b; ++i) {
          x1[i] = f * (*u)[i];
          u1[i] = f * free_acc_[i];
          size = std::max({size, std::abs(x1[i]), std::abs(u1[i])});
        }
      }
      record(r + 1, x1);
      for (std::size_t g = 0; g < groups; ++g) free_scale_[g] *= loads_[g].omega * eta_ / (r + 1);
      x = &x1;
      u = &u1;
      big = std::max(big, size);
      *largest = big;
      if (r + 1 >= 4 && size + previous <= 0.5 * kEpsilon * big) return r + 1;
      previous = size;
    }
    return -1;
  }
  // The rows of a window on which window_series' term r is exact: those at least r reaches from
  // an edge that is not an end of the structure.
  std::pair<Index, Index> window_exact_rows(const switching_detail::RowRanges::Range& window,
                                            int r) const {
    const auto [lo, hi] = window;
    const Index first = lo > 0 ? std::min<Index>(hi, lo + r * reach_) : lo;
    const Index last = hi < n_ ? std::max<Index>(first, hi - r * reach_) : hi;
    return {first, last};
  }
  // True when every spring's gap in the displacement x is on its mode's side of the kink (within
  // the kink tolerance): the check a smooth step's LCP makes at its end.
  bool modes_hold(const Vector& x) {
    end_gaps_.resize(m_);
    gap_band_.multiply(x.data(), end_gaps_.data());
    for (Index j = 0; j < m_; ++j) {
      if (signs_[j] * (end_gaps_[j] - gaps_[j]) < -kink_tolerance(j)) return false;
    }
    return true;
  }
  // The end of the free motion (every spring open) over the step from state_: T y plus the
  // loads' responses, the smooth step's formula with no spring force to approximate (the phases
  // of the step's start, from its series), into x and x'.
  void free_motion_end(Vector& x, Vector& u) {
    transition_.multiply(state_.data(), bar_.data());
    for (std::size_t g = 0; g < harmonics_.size(); ++g) {
      bar_ += phase_sin_[g] * harmonics_[g].sin_response + phase_cos_[g] * harmonics_[g].cos_response;
    }
    deinterleave_state(bar_, x, u);
  }
  void end_pieces() {
    for (Index i = 0; i < n_; ++i) {
      state_[2 * i] = xs_[0][i];
      state_[2 * i + 1] = us_[0][i];
    }
  }

  void step() {
    const double t = time();
    deinterleave_state(state_, xs_[0], us_[0]);
    collect_acting();
    taylor(t, eta_, d_ + 1, 0.0, false);
    if (o_.locate_switches && screen_fails()) {
      ++diagnostics_.screened;
      if (!this->gap_screen_clears(t)) {
        lcp_synced_ = false;
        switching(t);
        return;
      }
      ++diagnostics_.cleared;
    }
    transition_.multiply(state_.data(), bar_.data());
    for (std::size_t g = 0; g < harmonics_.size(); ++g) {
      bar_ += phase_sin_[g] * harmonics_[g].sin_response + phase_cos_[g] * harmonics_[g].cos_response;
    }
    if (end_derivative_) {
      const auto last = static_cast<std::size_t>(d_ + 1);
      ps_[last] = mode_.cwiseProduct(stiffnesses_.cwiseProduct(gw_[last]));
      slope_guess_ = static_cast<double>(d_ + 1) * ps_[last];
      for (int r = 1; r <= d_; ++r) slope_guess_ += static_cast<double>(r) * ps_[static_cast<std::size_t>(r)];
    }
    for (std::size_t r = 0; r < correction_.size(); ++r) {
      add_forces(correction_[r], correction_columns_[r], ps_[r], bar_);
    }
    const double largest = bar_.cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
    if (!(largest <= o_.divergence_bound)) throw_divergence(t + eta_, largest, o_.divergence_bound);
    if (m_ > 0) {
      for (Index i = 0; i < n_; ++i) half_[i] = bar_[2 * i];
      q_ = spring_offset_;
      spring_band_.multiply(half_.data(), spring_force_.data());
      q_ -= spring_force_;
      if (!lcp_synced_) {
        // Warm start from the mode (z must be zero outside the active set).
        z_ = mode_;
        solver_.reset_active_set(z_);
        lcp_synced_ = true;
      }
      stats_.lcp_pivots += solver_.solve_forces(q_, z_).pivots;
    }
    if (o_.locate_switches) {
      for (Index j = 0; j < m_; ++j) {
        if ((z_[j] > 0.0) != (mode_[j] > 0.0)) {
          ++diagnostics_.lcp_mismatches;
          lcp_synced_ = false;
          switching(t);
          return;
        }
      }
    } else {
      for (Index j = 0; j < m_; ++j) set_mode(j, z_[j] > 0.0);
      collect_acting();
    }
    state_.swap(bar_);
    add_forces(phi_, phi_columns_, z_, state_);
    if (end_derivative_ && o_.locate_switches && !acting_.empty()) {
      // Correct with the slope the new state gives (the mode is the same at both ends).
      for (Index i = 0; i < n_; ++i) half_[i] = state_[2 * i + 1];
      band_product(gap_band_, half_, spring_force_);
      slope_guess_ = eta_ * mode_.cwiseProduct(stiffnesses_.cwiseProduct(spring_force_)) -
                     slope_guess_;
      add_forces(slope_, slope_columns_, slope_guess_, state_);
    }
    finish_step();
  }

  // A switching step: corrected locally (see BandedSwitchingPimOptions::switch_correction) unless
  // the step must be halved or, automatically, the correction spreads over too many rows. After
  // such a step the next 1, 3, 7, ... 63 switching steps go to the whole state directly; a local
  // step resets that.
  void switching(double t) {
    using Mode = BandedSwitchingPimOptions::SwitchCorrection;
    if (correction_mode_ == Mode::whole_state) {
      this->switching_step(t, kMethodName);
      return;
    }
    const bool automatic = correction_mode_ == Mode::automatic;
    if (automatic && local_skip_ > 0) {
      --local_skip_;
      this->switching_step(t, kMethodName);
      return;
    }
    bool too_wide = false;
    if (this->local_switching_step(t, kMethodName, automatic ? n_ / 4 : n_, &too_wide)) {
      local_backoff_ = 1;
      return;
    }
    if (too_wide) {
      local_skip_ = local_backoff_;
      local_backoff_ = std::min(2 * local_backoff_ + 1, 63);
    }
    // The series buffers hold the local attempt's longer series: start the pieces afresh.
    this->switching_step(t, kMethodName, true);
  }

  void finish_step() {
    ++steps_;
    ++stats_.steps;
    ++diagnostics_.steps;
    // The whole state's largest entry (NaN when one is: the check below fails), vectorised, and
    // the positions' (the even entries).
    const double largest = state_.cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
    const double largest_x = state_.reshaped(2, n_).row(0).cwiseAbs().maxCoeff();
    x_scale_ = std::max(x_scale_, largest_x);
    if (!(largest <= o_.divergence_bound)) throw_divergence(time(), largest, o_.divergence_bound);
  }

  SwitchingPimOptions o_;
  Index n_, m_;
  int d_;
  double eta_;
  bool end_derivative_;
  BandedSwitchingPimOptions::SwitchCorrection correction_mode_;
  bool free_windows_;  // BandedSwitchingPimOptions::windowed_free_motion
  int local_skip_ = 0, local_backoff_ = 1;
  Index reach_ = 0;
  BandedLcpSolver solver_;
  bool lcp_synced_ = false;
  BandTruncation truncation_;
  BandedMatrix transition_;                 // T, interleaved state
  std::vector<HarmonicResponse> harmonics_; // interleaved
  std::vector<BandedMatrix> correction_, correction_columns_;  // coefficients of p_r (2n x m)
  BandedMatrix phi_, phi_columns_;          // ... of P_{k+1}
  BandedMatrix slope_, slope_columns_;      // ... of the end-slope correction
  RowSparse stiffness_part_, damping_part_, force_part_, gap_rows_, spring_rows_;
  BandedMatrix stiffness_band_, damping_band_, force_band_, gap_band_, spring_band_;
  Vector spring_force_ = Vector::Zero(m_);  // scratch: K2 W^T x or W^T x' of a step
  Vector gaps_, stiffnesses_, spring_offset_, abs_row_sums_;
  std::vector<LoadTerm> loads_;

  std::vector<int> acting_;
  Vector mode_, signs_;
  Vector state_, bar_, half_;
  Vector z_, q_, slope_guess_;
  double origin_ = 0.0;
  long steps_ = 0;
  double x_scale_ = 0.0;
  Vector position_, velocity_;
  Vector free_x_[2], free_u_[2], free_acc_, free_force_;  // window_series' terms, alternately
  std::vector<double> free_sin_, free_cos_, free_scale_;
  std::vector<int> force_set_;  // the springs whose free_force_ entry may be non-zero
  Vector end_gaps_;  // scratch of modes_hold
  IntegratorStats stats_;
  SwitchingPimDiagnostics diagnostics_;

  // advance_with_tangent: the step's LCP matrix and its bandwidths, the mode a step starts in and
  // its touching springs, the band LU of M_AA for the active set lu_set_, and scratch.
  BandedMatrix lcp_;
  Index lcp_lower_ = 0, lcp_upper_ = 0;
  Vector start_mode_;
  std::vector<int> start_acting_, lu_set_;
  std::vector<double> lu_, t_rhs_;
  Vector t_x_, t_u_, t_y_, t_bar_, t_acc_, t_g_, t_p_, t_slope_, t_z_;
  Vector t_half_ = Vector::Zero(n_);
  std::vector<switching_detail::RowRanges> force_window_;
  Vector w_x_[2], w_u_[2];  // the windowed recursion's terms, alternately
};

}  // namespace

std::unique_ptr<SwitchingPim> make_banded_switching_pim(const GapStructure& structure,
                                                        const BandedSwitchingPimOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("banded switching pim options: " + why);
  structure.validate();
  if (structure.load_groups().size() > 16) {
    throw InputError(fmt::format("loads: {} distinct frequencies; the switching PIM handles at "
                                 "most 16",
                                 structure.load_groups().size()));
  }
  const BandedLayout layout = banded_layout(structure);
  if (!layout.diagonal_mass) {
    throw InputError("banded switching pim: " + layout.why_not +
                     "; the banded method needs a lumped mass (use make_switching_pim)");
  }
  return std::make_unique<BandedStepper>(structure, options);
}

}  // namespace pwl
