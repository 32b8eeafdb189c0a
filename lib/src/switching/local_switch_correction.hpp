#pragma once
// Local switch corrections for the banded higher-order PIM (banded_switching_pim.hpp); private to
// pwl_core.
//
// A step in which springs switch is redone exactly on the Taylor series of the motion, piece by
// piece from switch to switch (ModeSeries::switching_step). Done on the whole state, each piece
// costs a series of O(n) terms, although a switch changes the motion only near the switching
// spring. Here the step is split instead as
//
//     y(t) = y_u(t) + δ(t),
//
// with y_u the motion of the mode the step starts in, m0, over the whole step (one Taylor series
// on the whole state, the series the global path computes for its first piece), and δ the
// correction the switches make. δ starts at zero at the first switch and obeys
//
//     δ'' = -M⁻¹ (K δ + C δ' + W p_m(δ)) - M⁻¹ W (c ∘ K2 (W^T x_u - Δ)),   c = mode - m0,
//
// where p_m(δ) = m ∘ K2 W^T δ are the forces of the current mode's touching springs: its only
// source is the force of the springs whose mode differs from m0, which is zero when they switch
// and grows from there. Its Taylor series in each piece is computed on the rows it can reach:
// the r-th term of a series whose terms couple rows at most `reach` apart (K, C and the springs'
// two ends) is zero beyond r · reach rows from the rows where δ or its source start, so the
// windowed series is the whole-state series of δ, term for term, not an approximation; between
// pieces δ's rows are trimmed where it is below ε² of the motion (no digit of the state). The
// switches are located on the gap polynomials of y_u + δ for the springs near the window and on
// y_u's alone for the others (one search for them, over the springs whose gaps can reach their
// kinks in the step, CandidateSprings, repeated only when a spring it found joins the window).
// The step's end is y_u(η) + δ(η). Work per switching step: one whole-state series (which every
// switching step pays to find its first switch; one product T y on the free motion below) and,
// per piece, O(terms · window) instead of O(terms · n).
//
// The free motion. y_u's whole-state series to rounding is most of what a locally corrected step
// costs (20 to 30 terms of O(n) each on the paper's chain, against one banded product T y).
// Where the motion stays within the step's windows (windowed_free_motion, the default, without
// a tangent or its record), y_u is instead the free motion, with every spring open, and the
// springs touching at the start join the correction's sources from σ = 0 (c = mode - 0):
//   - y_u(η) is T y plus the loads' responses, the smooth step's formula, which is exact here:
//     there is no spring force to approximate;
//   - y_u's gap polynomials come from its series on windows of rows around the springs the
//     step's gap screen left and the touching springs, each widened by 2 K reaches (K the
//     series' length, adapted from step to step as the gap screen's windows): the first K for
//     the series itself, the second for the springs the correction's rows reach. A spring's
//     coefficients are exact when its rows are among the exact rows of the last term;
//   - the first switch is searched among the open springs the screen left (those it cleared are
//     trusted, as in every smooth step), and later ones among them and the springs near δ.
// The step goes back to the whole state's series when the screen left no spring (a switch found
// by the LCP), when the windows cover a quarter of the rows, when a window's series does not
// converge within K terms, when a spring the screen left sits on its kink pointing the other way,
// when δ reaches a spring beyond the windows' exact rows, or when a spring ends the step on the
// wrong side of its kink for its mode (the end check a smooth step's LCP makes, here on the
// springs the searches trusted to the screen). The two forms agree to rounding and the band's
// truncation of T (1e-15 of each block), not to the bit; steps with a tangent or its record
// always take the whole state's series. On the paper's 1000-mass chain at η = 0.4 s
// from rest to 200 s, 186 of its 193 local steps take the free motion.
//
// The tangent map follows the same split with the same pieces: the whole-step series of y_u's
// tangent in m0, and the windowed series of δ's, whose source is c ∘ K2 W^T of y_u's tangent (no
// saltation term: the vector field is continuous), its rows trimmed by its own size (its source,
// unlike the state's, is not zero at the switch). The record of a locally corrected step (its
// pieces, their lengths and terms, the springs that switch) is kept for replay, so a replayed
// tangent is bit for bit the one advance_with_tangent gives.
//
// The global path (ModeSeries::switching_step) stays the fallback: when y_u's series does not
// converge over the whole step within max_series_terms (it then halves pieces), and when the
// correction spreads over more rows than the caller allows (springs switching all along a chain
// at once, where a window is no cheaper than the whole state: the stepper's switch_correction).
//
// The split is the variation-of-constants view of a switch as a local perturbation of a linear
// flow (Hochbruck & Ostermann, Acta Numerica 19 (2010) 209-286, §2); the finite reach of each
// Taylor term is what makes banded exponentials of chains possible in the first place (He, Gao &
// Zhong, Appl. Math. Mech. 39(7) (2018) 737-749).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "event/event_location.hpp"
#include "pwl/errors.hpp"
#include "pwl/types.hpp"
#include "switching/switching_pim_detail.hpp"

namespace pwl::switching_detail {

// Sorted, disjoint half-open row ranges [first, last).
class RowRanges {
 public:
  using Range = std::pair<Index, Index>;
  void clear() { ranges_.clear(); }
  bool empty() const { return ranges_.empty(); }
  const std::vector<Range>& ranges() const { return ranges_; }
  // Appends a range; call normalize() after the last.
  void add(Index first, Index last) {
    if (first < last) ranges_.emplace_back(first, last);
  }
  void normalize() {
    std::sort(ranges_.begin(), ranges_.end());
    std::size_t kept = 0;
    for (std::size_t i = 0; i < ranges_.size(); ++i) {
      if (kept > 0 && ranges_[i].first <= ranges_[kept - 1].second) {
        ranges_[kept - 1].second = std::max(ranges_[kept - 1].second, ranges_[i].second);
      } else {
        ranges_[kept++] = ranges_[i];
      }
    }
    ranges_.resize(kept);
  }
  // Every range widened by `by` on both sides, clipped to [0, n).
  void widen_from(const RowRanges& other, Index by, Index n) {
    ranges_.clear();
    for (const Range& r : other.ranges_) add(std::max<Index>(0, r.first - by), std::min(n, r.second + by));
    normalize();
  }
  Index rows() const {
    Index count = 0;
    for (const Range& r : ranges_) count += r.second - r.first;
    return count;
  }
  template <class F>
  void for_each_row(F&& f) const {
    for (const Range& r : ranges_) {
      for (Index i = r.first; i < r.second; ++i) f(i);
    }
  }

 private:
  std::vector<Range> ranges_;
};

// The coefficients b_r of p(σ0 + ρ τ) = Σ b_r τ^r for p(σ) = Σ_{r<=R} a_r σ^r (a Taylor shift by
// repeated synthetic division, O(R²)), into b[0..R]; a and b may not overlap.
inline void shift_polynomial(const double* a, int R, double sigma0, double rho, double* b) {
  for (int r = 0; r <= R; ++r) b[r] = a[r];
  for (int k = 0; k < R; ++k) {
    for (int i = R - 1; i >= k; --i) b[i] += sigma0 * b[i + 1];
  }
  double power = 1.0;
  for (int r = 0; r <= R; ++r) {
    b[r] *= power;
    power *= rho;
  }
}

// CRTP mixin of the banded switching stepper (a friend of it, as of ModeSeries, whose series
// buffers, search and tangent it uses). The stepper provides reach_ (see above), its sparse parts
// stiffness_part_, damping_part_, force_part_ (row-major) and gap_rows_, the members ModeSeries
// names, and for the free motion free_windows_, acting_, spring_span, window_series,
// window_exact_rows, modes_hold and free_motion_end.
template <class Stepper>
class LocalSwitchCorrection {
 protected:
  // One piece of a locally corrected step: from σ0 (a fraction of the step) for ρ of it, the
  // series of δ with `terms` terms, ending at τ (a fraction of the piece), and the springs that
  // switch around it.
  struct LocalPiece {
    double sigma0 = 0.0, rho = 0.0, tau = 0.0;
    int terms = 0;
    std::vector<Index> flips;    // springs settled on their kink at its start
    std::vector<Index> toggles;  // springs that switch at its end
  };
  struct LocalStep {
    Vector base_mode;  // m0
    int terms = 0;     // of y_u's series
    std::vector<LocalPiece> pieces;
    std::vector<Index> first_toggles;  // the springs that switch at the first crossing
    std::vector<Index> sources;        // every spring whose mode differs from m0 in some piece
    // Memory held, for the record's bound.
    std::size_t bytes() const {
      std::size_t b = sizeof(LocalStep) + static_cast<std::size_t>(base_mode.size()) * sizeof(double) +
                      (first_toggles.size() + sources.size()) * sizeof(Index);
      for (const LocalPiece& p : pieces) b += sizeof(LocalPiece) + (p.flips.size() + p.toggles.size()) * sizeof(Index);
      return b;
    }
  };

  Stepper& me() { return static_cast<Stepper&>(*this); }

  // Sizes the per-spring lists; the per-row terms of δ are allocated by the first local step.
  void size_local(Index m) {
    source_row_.assign(static_cast<std::size_t>(m), -1);
    free_row_.assign(static_cast<std::size_t>(m), -1);
    in_mask_.assign(static_cast<std::size_t>(m), 0);
    base_mode_ = Vector::Zero(m);
  }

  void clear_local_records() {
    local_records_.clear();
    local_record_bytes_ = 0;
  }

  // The tangent of the recorded step `index` applied to `tangent` (replay).
  void replay_local_step(Index index, Matrix& tangent) {
    local_tangent(local_records_[static_cast<std::size_t>(index)], tangent);
  }

  // The switching step from the start in the series buffers (the terms up to d + 1 of the
  // current mode computed, as ModeSeries::switching_step expects), corrected locally. Returns
  // false, having changed nothing but the mode of springs settled on their kinks at the start,
  // when the step must take the global path: y_u's series needs a halved step, or the
  // correction's rows exceed max_rows (then *too_wide is set; the work done is dropped).
  bool local_switching_step(double t0, const char* method, Index max_rows, bool* too_wide) {
    Stepper& st = me();
    if (st.free_windows_ && st.tangent_ == nullptr && !st.noting() &&
        free_motion_step(t0, method, max_rows)) {
      return true;
    }
    const int max_terms = st.o_.max_series_terms;
    int R = 0;
    int resume = st.d_;
    for (int guard = 0;; ++guard) {
      if (guard > 10000) return false;
      st.begin_piece();
      R = st.taylor(t0, st.eta_, max_terms, 0.5 * kEpsilon, true, resume);
      resume = 0;
      if (R >= max_terms) return false;
      if (st.prepare_polynomial(R)) {
        for (Index j : st.flip_) st.set_mode(j, !(st.mode_[j] > 0.0));
        continue;
      }
      break;
    }
    local_switches_ = 0;
    local_pieces_ = 0;
    local_rows_ = 0;
    terms_u_ = R;
    base_mode_ = st.mode_;
    scale_ = st.series_largest_;  // the largest entry of the terms 0 .. R
    // The step's record, for its tangent now (advance_with_tangent) or for a replay later.
    const bool keep = st.tangent_ != nullptr || st.noting();
    LocalStep record;
    if (keep) {
      record.base_mode = base_mode_;
      record.terms = R;
    }
    // The first switch, on y_u for every spring that can switch in the step (the first piece has
    // δ = 0); the same springs for the later searches on y_u (outside_search).
    outside_.select(st.poly_, st.settings_);
    {
      const event_detail::SearchResult& first = st.locator_.find_first_crossing(
          outside_.poly, outside_.start, 1.0, outside_.settings);
      st.diagnostics_.gap_samples += first.samples;
      if (!first.found) return finish_local(std::move(record), keep);
      sigma_ = first.at.t;
      outside_.springs_of(first, found_);
    }
    ensure_terms(max_terms);
    // A throw from here on (a step the springs chatter through, a series that does not converge)
    // must not leave δ's rows or the mask behind for the next step after set_state.
    try {
      return local_pieces(t0, method, max_rows, too_wide, std::move(record), keep);
    } catch (...) {
      discard_local();
      throw;
    }
  }

 private:
  // The local switching step on the free motion (see the file's comment): y_u is the motion with
  // every spring open, its end T y from the stepper (free_motion_end), its gap polynomials from
  // its series on windows of rows around the springs the step's gap screen left and the springs
  // touching at the start (the stepper's window_series), and those touching springs are sources
  // of δ from the start on. False, with the modes and buffers of the step's start, when that
  // cannot decide the step alone: no spring left by the screen (an LCP mismatch), windows over a
  // quarter of the rows, a window's series that does not converge, a spring on its kink that
  // must switch at the start, a correction too wide or reaching springs beyond the windows'
  // exact rows, or a spring on the wrong side of its kink at the end. The searches' samples and
  // halved pieces of such an attempt stay counted in the diagnostics (work done).
  bool free_motion_step(double t0, const char* method, Index max_rows) {
    try {
      return free_motion_attempt(t0, method, max_rows);
    } catch (...) {
      // Nothing of the attempt may outlive it (free_row_'s marks, δ's rows).
      discard_local();
      reset_free();
      throw;
    }
  }
  bool free_motion_attempt(double t0, const char* method, Index max_rows) {
    Stepper& st = me();
    const int max_terms = st.o_.max_series_terms;
    free_springs_.clear();
    bool flagged = false;
    for (Index j = 0; j < st.m_; ++j) {
      if (st.screen_clears(j)) continue;
      flagged = true;
      if (!(st.mode_[j] > 0.0)) free_springs_.push_back(j);
    }
    if (!flagged) return false;
    // Each window: the springs' rows widened by K reaches for y_u's own series of up to K terms
    // and as many again for the springs the correction's series reaches. K follows the series
    // down to 4 terms more than they needed (one less per step, as the gap screen's windows);
    // a step whose series or correction outgrows it goes to the whole state's series and puts
    // K back to max_series_terms.
    const int K = free_terms_ > 0 ? std::min(max_terms, free_terms_) : max_terms;
    const Index margin = 2 * static_cast<Index>(K) * st.reach_;
    free_ranges_.clear();
    const auto add_window = [&](Index j) {
      const auto [lo, hi] = st.spring_span(j);
      free_ranges_.add(std::max<Index>(0, lo - margin), std::min(st.n_, hi + margin));
    };
    for (Index j : free_springs_) add_window(j);
    for (int j : st.acting_) add_window(j);
    free_ranges_.normalize();
    if (4 * free_ranges_.rows() >= st.n_) return false;
    // The scale of the whole state's series: the screen's terms (x to d + 1, x' to d).
    double scale = 0.0;
    for (int r = 0; r <= st.d_ + 1; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      scale = std::max(scale, st.xs_[ru].cwiseAbs().maxCoeff());
      if (r <= st.d_) scale = std::max(scale, st.us_[ru].cwiseAbs().maxCoeff());
    }
    // The gap coefficients of every spring within a window; kept for the springs whose rows are
    // among their window's exact rows of the last term.
    const auto stride = static_cast<std::size_t>(max_terms + 1);
    const auto& windows = free_ranges_.ranges();
    free_first_.clear();
    for (const RowRanges::Range& range : windows) {
      free_first_.push_back(free_named_.size());
      for (Index i = range.first; i < range.second; ++i) {
        for (typename Stepper::RowSparseMatrix::InnerIterator it(st.force_part_, i); it; ++it) {
          const Index j = it.col();
          if (free_row_[static_cast<std::size_t>(j)] != -1) continue;
          free_row_[static_cast<std::size_t>(j)] = static_cast<int>(free_named_.size());
          free_named_.push_back(j);
        }
      }
    }
    free_first_.push_back(free_named_.size());
    free_gaps_.assign(free_named_.size() * stride, 0.0);
    const int R = st.window_series(t0, free_ranges_, K, scale, true, &scale, [&](int r, const Vector& x) {
      for (std::size_t k = 0; k < free_named_.size(); ++k) {
        free_gaps_[k * stride + static_cast<std::size_t>(r)] = st.spring_stretch(free_named_[k], x);
      }
    });
    if (R < 0) {
      free_terms_ = 0;
      reset_free();
      return false;
    }
    free_terms_ = std::max(R + 4, K - 1);
    for (std::size_t w = 0; w < windows.size(); ++w) {
      const auto [first, last] = st.window_exact_rows(windows[w], R);
      for (std::size_t k = free_first_[w]; k < free_first_[w + 1]; ++k) {
        const auto [lo, hi] = st.spring_span(free_named_[k]);
        if (lo < first || hi > last) free_row_[static_cast<std::size_t>(free_named_[k])] = -2;
      }
    }
    // The open springs the screen left: on their kinks first, then the searches on y_u alone.
    const auto count = static_cast<Index>(free_springs_.size());
    free_poly_.c.resize(count, R + 1);
    for (Index k = 0; k < count; ++k) {
      const Index j = free_springs_[static_cast<std::size_t>(k)];
      const int row = free_row_[static_cast<std::size_t>(j)];
      if (row < 0) {
        reset_free();
        return false;
      }
      const double sign = st.signs_[j];
      for (int r = 0; r <= R; ++r) {
        free_poly_.c(k, r) = sign * free_gaps_[static_cast<std::size_t>(row) * stride + static_cast<std::size_t>(r)];
      }
      free_poly_.c(k, 0) -= sign * st.gaps_[j];
    }
    if (st.settle_kinks(free_poly_, free_springs_.data(), free_start_, free_settings_, flips_)) {
      reset_free();
      return false;
    }
    free_base_ = true;
    free_short_ = false;
    free_rejected_ = false;
    free_start_mode_ = st.mode_;
    local_switches_ = 0;
    local_pieces_ = 0;
    local_rows_ = 0;
    terms_u_ = R;
    base_mode_.setZero(st.m_);
    scale_ = scale;
    outside_.select(free_poly_, free_settings_, &free_springs_, st.m_);
    found_.clear();
    sigma_ = 0.0;
    ensure_terms(max_terms);
    bool done = false;
    if (st.acting_.empty()) {
      // δ starts at the first switch, located on y_u.
      const event_detail::SearchResult& first = st.locator_.find_first_crossing(
          outside_.poly, outside_.start, 1.0, outside_.settings);
      st.diagnostics_.gap_samples += first.samples;
      if (!first.found) {
        changed_.clear();
        done = finish_local(LocalStep(), false);
      } else {
        sigma_ = first.at.t;
        outside_.springs_of(first, found_);
      }
    }
    if (!done && !free_rejected_) {
      bool wide = false;
      done = local_pieces(t0, method, max_rows, &wide, LocalStep(), false);
    }
    if (done) return true;
    // Too wide, beyond the windows (the next windows start again from max_series_terms), or a
    // spring on the wrong side at the end: the whole state's series decides the step.
    if (free_short_) free_terms_ = 0;
    reset_free();
    return false;
  }

  // y_u's scaled gap coefficient r of spring j: the whole state's series, or, in a free motion
  // step, the windows' (a spring beyond their exact rows marks the step short and reads 0).
  double u_gap(int r, Index j) {
    if (!free_base_) return me().gw_[static_cast<std::size_t>(r)][j];
    const int row = free_row_[static_cast<std::size_t>(j)];
    if (row < 0) {
      free_short_ = true;
      return 0.0;
    }
    return free_gaps_[static_cast<std::size_t>(row) * static_cast<std::size_t>(me().o_.max_series_terms + 1) +
                      static_cast<std::size_t>(r)];
  }

  void reset_free() {
    for (Index j : free_named_) free_row_[static_cast<std::size_t>(j)] = -1;
    free_named_.clear();
    free_base_ = false;
    free_short_ = false;
    free_rejected_ = false;
  }

  // The pieces of local_switching_step from its first switch (found_, at sigma_).
  bool local_pieces(double t0, const char* method, Index max_rows, bool* too_wide,
                    LocalStep&& moved_record, bool keep) {
    Stepper& st = me();
    const int max_terms = st.o_.max_series_terms;
    LocalStep record = std::move(moved_record);
    changed_.clear();
    mask_.clear();
    support_.clear();
    out_valid_ = false;
    if (free_base_) {
      // The springs touching at the start differ from the free motion's mode from σ = 0 on.
      for (int j : st.acting_) note_change(j);
    }
    for (Index j : found_) local_toggle(j);
    if (keep) {
      record.first_toggles = found_;
      record.sources = changed_;
    }
    if (sigma_ >= 1.0) return finish_local(std::move(record), keep);
    add_changed_rows(support_);

    int guard = 0;
    pending_flips_.clear();
    while (sigma_ < 1.0) {
      if (++guard > 10000) {
        throw DivergenceError(fmt::format(
            "{}: more than 10000 pieces in the step at t = {}: the springs chatter at their "
            "kinks",
            method, t0));
      }
      double rho = 1.0 - sigma_;
      bool whole = true;
      int terms = 0;
      build_sources(sigma_, rho, true);
      while (true) {
        terms = delta_series(rho * st.eta_, st.mode_, 0, max_terms, scale_);
        if (terms < max_terms) break;
        clear_terms(terms);
        rho *= 0.5;
        whole = false;
        ++st.diagnostics_.halved_pieces;
        if (!(rho > 0.0)) throw DivergenceError(fmt::format("{}: the Taylor series did not converge", method));
        build_sources(sigma_, rho, true);
      }
      ++local_pieces_;
      local_rows_ += rows_[static_cast<std::size_t>(terms)].rows();
      if (rows_[static_cast<std::size_t>(terms)].rows() > max_rows) {
        clear_terms(terms);
        abandon();
        *too_wide = true;
        return false;
      }
      // The springs whose gaps δ reaches join the mask for good: they are searched on y_u + δ
      // from now on, the others on y_u alone.
      bool grew = false;
      rows_[static_cast<std::size_t>(terms)].for_each_row([&](Index i) {
        for (typename Stepper::RowSparseMatrix::InnerIterator it(st.force_part_, i); it; ++it) {
          const auto j = static_cast<std::size_t>(it.col());
          if (!in_mask_[j]) {
            in_mask_[j] = 1;
            mask_.push_back(it.col());
            grew = true;
          }
        }
      });
      if (grew) std::sort(mask_.begin(), mask_.end());
      window_polynomial(sigma_, rho, terms);
      if (free_short_) {
        // A free motion step whose correction reaches beyond the windows: the caller redoes it
        // with the whole state's series.
        clear_terms(terms);
        abandon();
        return false;
      }
      if (st.settle_kinks(local_poly_, mask_.data(), local_start_, local_settings_, flips_)) {
        // A spring on its kink whose motion points to the other side: its mode was a guess;
        // correct it (not counted as a switch) and redo the piece.
        clear_terms(terms);
        for (Index j : flips_) {
          set_local_mode(j);
          pending_flips_.push_back(j);
        }
        add_changed_rows(support_);
        continue;
      }
      const event_detail::SearchResult& inside =
          st.locator_.find_first_crossing(local_poly_, local_start_, 1.0, local_settings_);
      st.diagnostics_.gap_samples += inside.samples;
      const bool inside_found = inside.found;
      const double tau_inside = inside.found ? inside.at.t : 2.0;
      found_.clear();
      for (Index k : inside.springs) found_.push_back(mask_[static_cast<std::size_t>(k)]);
      outside_search();
      // The piece ends at the first switch, inside the window or outside it (both at a tie).
      const double tau_outside = out_found_ ? (out_sigma_ - sigma_) / rho : 2.0;
      double tau = 1.0, next = whole ? 1.0 : sigma_ + rho;
      if (out_found_ && tau_outside <= 1.0 && tau_outside <= tau_inside) {
        tau = tau_outside;
        next = std::min(1.0, out_sigma_);
        const bool tie = inside_found && tau_inside == tau_outside;
        if (!tie) found_.clear();
        found_.insert(found_.end(), out_springs_.begin(), out_springs_.end());
        out_valid_ = false;
      } else if (inside_found) {
        tau = tau_inside;
        next = tau >= 1.0 && whole ? 1.0 : sigma_ + tau * rho;
      } else {
        found_.clear();
      }
      if (keep) {
        LocalPiece piece;
        piece.sigma0 = sigma_;
        piece.rho = rho;
        piece.tau = tau;
        piece.terms = terms;
        piece.flips = pending_flips_;
        piece.toggles = found_;
        record.pieces.push_back(std::move(piece));
      }
      end_piece(tau, terms, scale_);
      sigma_ = next;
      for (Index j : found_) local_toggle(j);
      if (keep) {
        for (const std::vector<Index>* list : {&pending_flips_, &found_}) {
          for (Index j : *list) {
            if (std::find(record.sources.begin(), record.sources.end(), j) == record.sources.end()) {
              record.sources.push_back(j);
            }
          }
        }
      }
      pending_flips_.clear();
      add_changed_rows(support_);
    }
    return finish_local(std::move(record), keep);
  }

  // Everything a local step leaves in the buffers, dropped (after a throw).
  void discard_local() {
    clear_terms(live_terms_);
    support_.for_each_row([&](Index i) {
      dx_[0][i] = 0.0;
      du_[0][i] = 0.0;
    });
    support_.clear();
    for (Index j : mask_) in_mask_[static_cast<std::size_t>(j)] = 0;
    mask_.clear();
    changed_.clear();
    reset_source_rows();
  }

  // The step's end y_u(η) + δ(η), its tangent, and the stepper's end of step. False, with the
  // step abandoned (abandon()), when a free motion step ends with a spring on the wrong side.
  bool finish_local(LocalStep&& record, bool keep) {
    Stepper& st = me();
    if (free_base_) {
      st.free_motion_end(st.vx_, st.vu_);
      support_.for_each_row([&](Index i) {
        st.vx_[i] += dx_[0][i];
        st.vu_[i] += du_[0][i];
      });
      // The springs the free motion's searches trusted to the first screen are checked at the
      // end, as a smooth step's LCP checks them: one on the wrong side of its kink for its mode
      // sends the step back (free_rejected_) to the whole state's series, which searches them all.
      if (!st.modes_hold(st.vx_)) {
        free_rejected_ = true;
        abandon();
        return false;
      }
      ++st.diagnostics_.free_windowed;
      reset_free();
    } else {
      st.evaluate_series(terms_u_, 1.0);
      support_.for_each_row([&](Index i) {
        st.vx_[i] += dx_[0][i];
        st.vu_[i] += du_[0][i];
      });
    }
    support_.for_each_row([&](Index i) {
      dx_[0][i] = 0.0;
      du_[0][i] = 0.0;
    });
    st.xs_[0].swap(st.vx_);
    st.us_[0].swap(st.vu_);
    st.end_pieces();
    ++st.diagnostics_.switching_steps;
    ++st.diagnostics_.local_steps;
    st.diagnostics_.pieces += 1 + local_pieces_;
    st.diagnostics_.local_rows += local_rows_;
    if (keep) {
      if (st.tangent_ != nullptr) local_tangent(record, *st.tangent_);
      if (st.noting()) {
        // Kept within the same bound as the record's entries (ModeSeries::kRecordLimit of them):
        // beyond it the record is dropped (no replay) rather than grow without bound.
        const std::size_t bytes = record.bytes();
        if (local_record_bytes_ + bytes > Stepper::kRecordLimit * sizeof(typename Stepper::TangentOp)) {
          st.end_record();
        } else {
          typename Stepper::TangentOp op;
          op.kind = Stepper::TangentOp::Kind::local_step;
          op.spring = static_cast<Index>(local_records_.size());
          local_records_.push_back(std::move(record));
          local_record_bytes_ += bytes;
          st.note(op);
        }
      }
    }
    support_.clear();
    for (Index j : mask_) in_mask_[static_cast<std::size_t>(j)] = 0;
    mask_.clear();
    changed_.clear();
    reset_source_rows();
    st.finish_step();
    return true;
  }

  // A located switch of spring j (counted), and the list of springs whose mode differs from m0.
  void local_toggle(Index j) {
    me().toggle(j);
    ++local_switches_;
    note_change(j);
  }

  // Back to the step's start in m0: modes, counts and the correction's rows (the record keeps
  // the mode changes and their reversal, which cancel).
  void abandon() {
    Stepper& st = me();
    if (free_base_) {
      // The base is the free motion: back to the modes of the start.
      for (Index j = 0; j < st.m_; ++j) st.set_mode(j, free_start_mode_[j] > 0.0);
    } else {
      for (Index j : changed_) st.set_mode(j, base_mode_[j] > 0.0);
    }
    st.diagnostics_.switches -= local_switches_;
    st.stats_.kink_events -= local_switches_;
    discard_local();
  }
  // A mode settled on its kink (not counted).
  void set_local_mode(Index j) {
    Stepper& st = me();
    st.set_mode(j, !(st.mode_[j] > 0.0));
    note_change(j);
  }
  void note_change(Index j) {
    Stepper& st = me();
    const auto it = std::find(changed_.begin(), changed_.end(), j);
    const bool differs = (st.mode_[j] > 0.0) != (base_mode_[j] > 0.0);
    if (differs && it == changed_.end()) changed_.push_back(j);
    if (!differs && it != changed_.end()) changed_.erase(it);
  }

  // The rows of the changed springs' ends added to `rows`.
  void add_changed_rows(RowRanges& rows) {
    Stepper& st = me();
    for (Index j : changed_) {
      for (typename Stepper::RowSparseMatrix::InnerIterator it(st.gap_rows_, j); it; ++it) {
        rows.add(it.col(), it.col() + 1);
      }
    }
    rows.normalize();
  }

  // The sources of δ's series in a piece from σ0 for ρ of the step: for each changed spring j,
  // c_j K2_j (W^T x_u - Δ)_j as scaled Taylor coefficients of the piece, from y_u's gap
  // polynomial (offset true: the state's) or from the tangent's gap coefficients tangent_gaps_
  // (offset false).
  void build_sources(double sigma0, double rho, bool state) {
    Stepper& st = me();
    const int R = state ? terms_u_ : tangent_terms_;
    reset_source_rows();
    source_set_ = changed_;
    sources_.resize(static_cast<Index>(changed_.size()), R + 1);
    coefficients_.resize(static_cast<std::size_t>(R + 1));
    shifted_.resize(static_cast<std::size_t>(R + 1));
    for (std::size_t k = 0; k < changed_.size(); ++k) {
      const Index j = changed_[k];
      source_row_[static_cast<std::size_t>(j)] = static_cast<int>(k);
      for (int r = 0; r <= R; ++r) {
        coefficients_[static_cast<std::size_t>(r)] =
            state ? u_gap(r, j) : tangent_gaps_(source_index(j), r);
      }
      shift_polynomial(coefficients_.data(), R, sigma0, rho, shifted_.data());
      const double c = (st.mode_[j] > 0.0 ? 1.0 : 0.0) - (base_mode_[j] > 0.0 ? 1.0 : 0.0);
      for (int r = 0; r <= R; ++r) {
        double g = shifted_[static_cast<std::size_t>(r)];
        if (state && r == 0) g -= st.gaps_[j];
        sources_(static_cast<Index>(k), r) = c * st.stiffnesses_[j] * g;
      }
    }
  }
  void reset_source_rows() {
    for (Index j : source_set_) source_row_[static_cast<std::size_t>(j)] = -1;
    source_set_.clear();
  }
  // Terms 0..terms of δ, allocated once (n each, zero outside their rows).
  void ensure_terms(int terms) {
    const Index n = me().n_;
    const auto count = static_cast<std::size_t>(terms + 1);
    if (dx_.size() >= count) return;
    dx_.resize(count, Vector::Zero(n));
    du_.resize(count, Vector::Zero(n));
    rows_.resize(count);
    scratch_x_ = Vector::Zero(n);
    scratch_u_ = Vector::Zero(n);
  }
  Index source_index(Index j) const {
    const auto it = std::find(tangent_sources_->begin(), tangent_sources_->end(), j);
    return static_cast<Index>(it - tangent_sources_->begin());
  }

  // The scaled Taylor terms of δ for a piece of length h from dx_[0], du_[0] (zero outside
  // rows_[0] = support_), the current sources_ and the mode `mode`: term r on rows_[r] (support_
  // widened by r · reach). Stops when two consecutive terms are below rounding of `scale`, not
  // before min_terms; returns the index of the last term, or max_terms when not converged.
  int delta_series(double h, const Vector& mode, int min_terms, int max_terms, double scale) {
    Stepper& st = me();
    rows_[0] = support_;
    double largest = scale, previous = 0.0;
    rows_[0].for_each_row([&](Index i) {
      previous = std::max({previous, std::abs(dx_[0][i]), std::abs(du_[0][i])});
    });
    largest = std::max(largest, previous);
    const Index n = st.n_;
    for (int r = 0; r < max_terms; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      rows_[ru + 1].widen_from(rows_[ru], st.reach_, n);
      const Vector& x = dx_[ru];
      const Vector& u = du_[ru];
      Vector& x1 = dx_[ru + 1];
      Vector& u1 = du_[ru + 1];
      const double f = h / (r + 1);
      double size = 0.0;
      rows_[ru + 1].for_each_row([&](Index i) {
        const double acc = st.row_acceleration(i, x, u, [&](Index j) {
          double p = mode[j] > 0.0 ? st.stiffnesses_[j] * st.spring_stretch(j, x) : 0.0;
          const int k = source_row_[static_cast<std::size_t>(j)];
          if (k >= 0 && r < sources_.cols()) p += sources_(k, r);
          return p;
        });
        x1[i] = f * u[i];
        u1[i] = f * acc;
        size = std::max({size, std::abs(x1[i]), std::abs(u1[i])});
      });
      largest = std::max(largest, size);
      live_terms_ = r + 1;
      if (r + 1 >= min_terms && r + 1 >= 4 && size + previous <= 0.5 * kEpsilon * largest) {
        return r + 1;
      }
      previous = size;
    }
    return max_terms;
  }

  // Zero the terms 1..terms of δ (their rows).
  void clear_terms(int terms) {
    live_terms_ = 0;
    for (int r = 1; r <= terms; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      rows_[ru].for_each_row([&](Index i) {
        dx_[ru][i] = 0.0;
        du_[ru][i] = 0.0;
      });
    }
  }

  // δ at τ of the piece into dx_[0], du_[0], its terms cleared; support_ becomes the rows where δ
  // is above ε² of `scale` (the range of each run of rows, trimmed at its ends).
  void end_piece(double tau, int terms, double scale) {
    evaluate_delta(tau, terms);
    const double floor = kEpsilon * kEpsilon * scale;
    RowRanges kept;
    for (const RowRanges::Range& range : rows_[static_cast<std::size_t>(terms)].ranges()) {
      Index first = range.first, last = range.second;
      const auto small = [&](Index i) {
        return std::abs(scratch_x_[i]) <= floor && std::abs(scratch_u_[i]) <= floor;
      };
      while (first < last && small(first)) ++first;
      while (last > first && small(last - 1)) --last;
      kept.add(first, last);
    }
    kept.normalize();
    rows_[static_cast<std::size_t>(terms)].for_each_row([&](Index i) {
      scratch_x_[i] = 0.0;
      scratch_u_[i] = 0.0;
    });
    support_ = kept;
    // Rows of rows_[terms] no longer in support_: zero them in dx_[0], du_[0].
    rows_[static_cast<std::size_t>(terms)].for_each_row([&](Index i) {
      if (!contains(support_, i)) {
        dx_[0][i] = 0.0;
        du_[0][i] = 0.0;
      }
    });
  }

  static bool contains(const RowRanges& rows, Index i) {
    const auto& r = rows.ranges();
    auto it = std::upper_bound(r.begin(), r.end(), i,
                               [](Index v, const RowRanges::Range& range) { return v < range.first; });
    if (it == r.begin()) return false;
    --it;
    return i < it->second;
  }

  // Σ_r δ_r τ^r on rows_[terms] into dx_[0], du_[0] (and a copy in scratch_x_, scratch_u_), the
  // terms 1..terms cleared.
  void evaluate_delta(double tau, int terms) {
    rows_[static_cast<std::size_t>(terms)].for_each_row([&](Index i) {
      double x = dx_[static_cast<std::size_t>(terms)][i], u = du_[static_cast<std::size_t>(terms)][i];
      for (int r = terms - 1; r >= 0; --r) {
        x = x * tau + dx_[static_cast<std::size_t>(r)][i];
        u = u * tau + du_[static_cast<std::size_t>(r)][i];
      }
      scratch_x_[i] = x;
      scratch_u_[i] = u;
    });
    clear_terms(terms);
    rows_[static_cast<std::size_t>(terms)].for_each_row([&](Index i) {
      dx_[0][i] = scratch_x_[i];
      du_[0][i] = scratch_u_[i];
    });
  }

  // The mode-signed gap polynomials of the masked springs on the piece: y_u's shifted to it plus
  // W^T of δ's terms.
  void window_polynomial(double sigma0, double rho, int terms) {
    Stepper& st = me();
    const int R = std::max(terms_u_, terms);
    const auto count = static_cast<Index>(mask_.size());
    local_poly_.c.setZero(count, R + 1);
    coefficients_.resize(static_cast<std::size_t>(terms_u_ + 1));
    shifted_.resize(static_cast<std::size_t>(terms_u_ + 1));
    for (Index k = 0; k < count; ++k) {
      const Index j = mask_[static_cast<std::size_t>(k)];
      for (int r = 0; r <= terms_u_; ++r) coefficients_[static_cast<std::size_t>(r)] = u_gap(r, j);
      shift_polynomial(coefficients_.data(), terms_u_, sigma0, rho, shifted_.data());
      const double sign = st.signs_[j];
      for (int r = 0; r <= R; ++r) {
        double g = r <= terms_u_ ? shifted_[static_cast<std::size_t>(r)] : 0.0;
        if (r == 0) g -= st.gaps_[j];
        if (r <= terms) {
          for (typename Stepper::RowSparseMatrix::InnerIterator w(st.gap_rows_, j); w; ++w) {
            g += w.value() * dx_[static_cast<std::size_t>(r)][w.col()];
          }
        }
        local_poly_.c(k, r) = sign * g;
      }
    }
  }

  // The first switch after σ of a spring outside the mask, on y_u's gaps: kept while none of the
  // springs it found has joined the mask (the mask only grows within a step).
  void outside_search() {
    Stepper& st = me();
    if (out_valid_) {
      bool still = true;
      for (Index j : out_springs_) still = still && !in_mask_[static_cast<std::size_t>(j)];
      if (still && (!out_found_ || out_sigma_ >= sigma_)) return;
    }
    out_valid_ = true;
    event_detail::SearchSettings& s = outside_.settings;
    for (Index j : mask_) {
      const int k = outside_.row_of[static_cast<std::size_t>(j)];
      if (k >= 0) s.certified_until[k] = std::numeric_limits<double>::infinity();
    }
    outside_start_ = event_detail::GapSample();
    outside_.poly.sample(outside_start_, sigma_, outside_start_);
    const event_detail::SearchResult& r =
        st.locator_.find_first_crossing(outside_.poly, outside_start_, 1.0, s);
    st.diagnostics_.gap_samples += r.samples;
    out_found_ = r.found;
    out_sigma_ = r.found ? r.at.t : 1.0;
    outside_.springs_of(r, out_springs_);
  }

  // The tangent of a recorded step applied to every column of Y.
  void local_tangent(const LocalStep& record, Matrix& Y) {
    Stepper& st = me();
    const Index n = st.n_;
    const Vector end_mode = st.mode_;
    const Vector saved_base = base_mode_;
    const int saved_terms = terms_u_;
    base_mode_ = record.base_mode;
    st.mode_ = record.base_mode;
    st.collect_acting();
    tangent_sources_ = &record.sources;
    const auto sources = static_cast<Index>(record.sources.size());
    const int limit = std::max(record.terms, st.o_.max_series_terms);
    ensure_terms(st.o_.max_series_terms);
    for (Index c = 0; c < Y.cols(); ++c) {
      for (Index j = 0; j < st.m_; ++j) st.mode_[j] = record.base_mode[j];
      // y_u's tangent over the whole step in m0, with the sources' gaps of its terms.
      st.tx_ = Y.col(c).head(n);
      st.tu_ = Y.col(c).tail(n);
      tangent_gaps_.setZero(sources, limit + 1);
      tangent_terms_ = 0;
      st.tangent_series(st.eta_, record.terms, 1.0, [&](int r, const Vector& x) {
        tangent_terms_ = r;
        for (Index k = 0; k < sources; ++k) {
          tangent_gaps_(k, r) = st.spring_stretch(record.sources[static_cast<std::size_t>(k)], x);
        }
      });
      double scale = std::max(st.tsx_.cwiseAbs().maxCoeff(), st.tsu_.cwiseAbs().maxCoeff());
      scale = std::max({scale, Y.col(c).cwiseAbs().maxCoeff()});
      // δ's tangent through the pieces, from zero, after the first crossing's switches.
      changed_.clear();
      support_.clear();
      const auto toggle_all = [&](const std::vector<Index>& springs) {
        for (Index j : springs) {
          st.mode_[j] = st.mode_[j] > 0.0 ? 0.0 : 1.0;
          note_change(j);
        }
        add_changed_rows(support_);
      };
      toggle_all(record.first_toggles);
      // Each piece as the state's, its rows trimmed by this column's own size (its source, unlike
      // the state's, is not zero at the switch).
      for (const LocalPiece& piece : record.pieces) {
        toggle_all(piece.flips);
        build_sources(piece.sigma0, piece.rho, false);
        const int terms = delta_series(piece.rho * st.eta_, st.mode_, piece.terms,
                                       st.o_.max_series_terms, scale);
        end_piece(piece.tau, terms, scale);
        toggle_all(piece.toggles);
      }
      for (Index i = 0; i < n; ++i) {
        Y(i, c) = st.tsx_[i];
        Y(n + i, c) = st.tsu_[i];
      }
      support_.for_each_row([&](Index i) {
        Y(i, c) += dx_[0][i];
        Y(n + i, c) += du_[0][i];
        dx_[0][i] = 0.0;
        du_[0][i] = 0.0;
      });
    }
    reset_source_rows();
    changed_.clear();
    support_.clear();
    tangent_sources_ = nullptr;
    st.mode_ = end_mode;
    st.collect_acting();
    base_mode_ = saved_base;
    terms_u_ = saved_terms;
  }

  // δ's terms (n each, zero outside their rows), the rows of each, the rows δ starts a piece on.
  std::vector<Vector> dx_, du_;
  std::vector<RowRanges> rows_;
  RowRanges support_;
  Vector scratch_x_, scratch_u_;
  Vector base_mode_;
  int terms_u_ = 0, live_terms_ = 0;  // live: terms 1..live of δ may be non-zero
  long local_switches_ = 0, local_pieces_ = 0, local_rows_ = 0;
  double sigma_ = 0.0, scale_ = 0.0;
  std::vector<Index> changed_, mask_, found_, flips_, pending_flips_;
  std::vector<int> source_row_;  // row of sources_ for a changed spring, -1 otherwise
  std::vector<Index> source_set_;  // the springs whose source_row_ is set
  std::vector<char> in_mask_;
  Matrix sources_;
  std::vector<double> coefficients_, shifted_;
  PolynomialGaps local_poly_;
  event_detail::GapSample local_start_, outside_start_;
  event_detail::SearchSettings local_settings_;
  bool out_valid_ = false, out_found_ = false;
  double out_sigma_ = 1.0;
  std::vector<Index> out_springs_;
  // The springs y_u's searches look at, with their polynomials and search settings.
  CandidateSprings outside_;
  // A free motion step: the springs the screen left, the windows, the series, the springs within
  // them (free_named_) with their rows in free_gaps_ (free_row_: -1 none, -2 not exact), and
  // the polynomials and search settings of the springs the screen left.
  bool free_base_ = false, free_short_ = false, free_rejected_ = false;
  int free_terms_ = 0;  // the windows' K; 0: max_series_terms
  Vector free_start_mode_;
  std::vector<Index> free_springs_, free_named_;
  std::vector<int> free_row_;
  std::vector<std::size_t> free_first_;  // the first of free_named_ in each window, and the end
  std::vector<double> free_gaps_;
  RowRanges free_ranges_;
  PolynomialGaps free_poly_;
  event_detail::GapSample free_start_;
  event_detail::SearchSettings free_settings_;
  // Tangent: y_u's tangent gaps at the step's sources, and the records kept for replay.
  Matrix tangent_gaps_;
  int tangent_terms_ = 0;
  const std::vector<Index>* tangent_sources_ = nullptr;
  std::vector<LocalStep> local_records_;
  std::size_t local_record_bytes_ = 0;
};

}  // namespace pwl::switching_detail
