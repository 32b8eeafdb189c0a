#pragma once
// The second gap screen of the banded higher-order PIM's smooth steps; private to pwl_core.
//
// Every step first screens the springs' gap polynomials of degree d + 1 (ModeSeries::
// screen_fails): a spring is cleared when a concave lower bound of its truncated gap stays
// positive over the step. A spring the bound cannot clear sends the step to the switching path,
// which expands the whole state to rounding before it searches for a switch. On a long chain
// most of those steps find none (at η = 0.4 s on the paper's 1000-mass chain, 208 of the 400
// screened steps): the bound is crude where a gap approaches its kink and turns back. This screen
// settles them locally: the gap polynomials to rounding of the springs the first screen left,
// from the Taylor series of the motion in the current mode on a window of rows around each, and
// the same search for a first crossing and for springs on their kinks as the switching step
// would run on them. No crossing: the step stays smooth (its formula is the one every other step
// uses); a crossing, a spring on its kink, or a window that is not cheaper than the whole state
// leave the step to the switching path, which decides as before. The springs the first screen
// cleared are trusted here as in every smooth step (the switching path searches every spring on
// the full series, so a flagged step used to look at them again).
//
// The window is exact, not an approximation: the r-th Taylor term couples rows at most r · reach
// apart (K, C and the springs' two ends), so the terms up to K of a spring's rows are those of
// the whole state when the window is its rows widened by K · reach. Term r is computed on the
// window's rows at least r · reach from an edge that is not an end of the structure: their
// neighbours are rows of term r - 1 computed before. K starts at max_series_terms and follows
// the screens' series down to 4 terms more than they need (one less per screen); a series that
// needs more than K sends its step to the switching path and puts K back to max_series_terms.
// The series stops as the whole state's does, once two consecutive terms are below ε/2 of the
// largest, measured on the rows computed for them (all the rows the spring's later terms up to K
// draw on): a stopping rule of the same kind as the whole state's, not a bound. The finite reach of each term is what makes banded exponentials of chains possible
// in the first place (He, Gao & Zhong, Appl. Math. Mech. 39(7) (2018) 737-749); the screen itself
// is the polynomial root exclusion of event_location.hpp on the gap's series.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "event/event_location.hpp"
#include "pwl/types.hpp"
#include "switching/local_switch_correction.hpp"
#include "switching/switching_pim_detail.hpp"

namespace pwl::switching_detail {

// A window's rows of one term (row `lo` first), read by the structure's row index.
struct WindowRows {
  const double* values;
  Index lo;
  double operator[](Index row) const { return values[row - lo]; }
};

// CRTP mixin of the banded switching stepper (a friend of it, whose ModeSeries buffers and search
// it uses): the stepper provides reach_, n_, m_, eta_, o_, mode_, signs_, gaps_, stiffnesses_,
// spring_offset_, loads_, gap_rows_, the row sums row_acceleration and spring_stretch (read
// through WindowRows), the series start xs_[0], us_[0] and the first screen's terms.
template <class Stepper>
class LocalGapScreen {
 protected:
  // True when every spring the first screen could not clear certainly keeps its mode over the
  // step from time t (the start in xs_[0], us_[0], the first screen's terms computed). False when
  // one may switch, one sits on its kink, the series does not converge within the window, or the
  // windows together cover a quarter of the rows or more (the switching path is then as cheap).
  bool gap_screen_clears(double t) {
    Stepper& st = static_cast<Stepper&>(*this);
    // The windows' margin K (above).
    const int most = st.o_.max_series_terms;
    const int K = window_terms_ > 0 ? std::min(most, window_terms_) : most;
    const Index margin = static_cast<Index>(K) * st.reach_;
    screen_springs_.clear();
    screen_ranges_.clear();
    for (Index j = 0; j < st.m_; ++j) {
      if (st.screen_clears(j)) continue;
      Index lo = st.n_, hi = 0;
      for (typename Stepper::RowSparseMatrix::InnerIterator it(st.gap_rows_, j); it; ++it) {
        lo = std::min(lo, it.col());
        hi = std::max(hi, it.col() + 1);
      }
      if (lo >= hi) return false;  // a spring without rows: nothing to window
      screen_springs_.push_back(j);
      screen_ranges_.add(std::max<Index>(0, lo - margin), std::min(st.n_, hi + margin));
    }
    if (screen_springs_.empty()) return true;
    screen_ranges_.normalize();
    if (4 * screen_ranges_.rows() >= st.n_) return false;

    const auto count = static_cast<Index>(screen_springs_.size());
    screen_coefficients_.assign(static_cast<std::size_t>(count) * static_cast<std::size_t>(K + 1), 0.0);
    int longest = 0;
    for (const RowRanges::Range& range : screen_ranges_.ranges()) {
      const int terms = window_series(st, t, range.first, range.second, K);
      if (terms < 0) {
        window_terms_ = 0;
        return false;
      }
      longest = std::max(longest, terms);
    }
    window_terms_ = std::max(longest + 4, K - 1);

    // The polynomials of the screened springs, mode-signed, and the switching step's search on
    // them: settled kinks first, then a first crossing on [0, 1].
    screen_poly_.c.resize(count, longest + 1);
    for (Index k = 0; k < count; ++k) {
      const Index j = screen_springs_[static_cast<std::size_t>(k)];
      const double* c = &screen_coefficients_[static_cast<std::size_t>(k) * static_cast<std::size_t>(K + 1)];
      for (int r = 0; r <= longest; ++r) screen_poly_.c(k, r) = st.signs_[j] * c[r];
      screen_poly_.c(k, 0) -= st.signs_[j] * st.gaps_[j];
    }
    if (st.settle_kinks(screen_poly_, screen_springs_.data(), screen_start_, screen_settings_, screen_flips_)) {
      return false;
    }
    const event_detail::SearchResult& found =
        st.locator_.find_first_crossing(screen_poly_, screen_start_, 1.0, screen_settings_);
    st.diagnostics_.gap_samples += found.samples;
    return !found.found;
  }

 private:
  // The Taylor series of the motion in the current mode about t for the step η on the rows
  // [lo, hi), each term on the rows it is exact on, until it converges (or K terms: -1). The gap coefficients W^T x_r of the screened springs whose rows lie there go to
  // screen_coefficients_ (K + 1 per spring). Returns the last term's index.
  int window_series(const Stepper& st, double t, Index lo, Index hi, int K) {
    const Index L = hi - lo;
    const auto width = static_cast<std::size_t>(L);
    window_x_.resize(2 * width);
    window_u_.resize(2 * width);
    double* x = window_x_.data();  // term r
    double* u = window_u_.data();
    double* x_next = x + width;
    double* u_next = u + width;
    for (Index i = 0; i < L; ++i) {
      x[i] = st.xs_[0][lo + i];
      u[i] = st.us_[0][lo + i];
    }
    const std::size_t groups = st.loads_.size();
    load_sin_.resize(groups);
    load_cos_.resize(groups);
    load_scale_.resize(groups);
    load_ds_.resize(groups);
    load_dc_.resize(groups);
    for (std::size_t g = 0; g < groups; ++g) {
      load_sin_[g] = std::sin(st.loads_[g].omega * t);
      load_cos_[g] = std::cos(st.loads_[g].omega * t);
      load_scale_[g] = 1.0;
    }
    // Term r is exact on the rows [first(r), last(r)): those at least r · reach from an edge of
    // the window that is not an end of the structure. Each term is computed there only: its
    // rows' neighbours (within reach) are exact rows of the term before.
    const bool open_lo = lo > 0, open_hi = hi < st.n_;
    auto first_row = [&](int r) { return open_lo ? std::min<Index>(L, r * st.reach_) : Index{0}; };
    auto last_row = [&](int r) {
      return open_hi ? std::max<Index>(first_row(r), L - r * st.reach_) : L;
    };
    window_springs_.clear();
    for (std::size_t k = 0; k < screen_springs_.size(); ++k) {
      typename Stepper::RowSparseMatrix::InnerIterator it(st.gap_rows_, screen_springs_[k]);
      if (it.col() >= lo && it.col() < hi) window_springs_.push_back(k);
    }
    auto record_gaps = [&](int r, const double* xr) {
      const WindowRows rows{xr, lo};
      for (std::size_t k : window_springs_) {
        screen_coefficients_[k * static_cast<std::size_t>(K + 1) + static_cast<std::size_t>(r)] =
            st.spring_stretch(screen_springs_[k], rows);
      }
    };
    auto size_of = [&](int r, const double* xr, const double* ur) {
      double size = 0.0;
      for (Index i = first_row(r); i < last_row(r); ++i) {
        size = std::max({size, std::abs(xr[i]), std::abs(ur[i])});
      }
      return size;
    };
    record_gaps(0, x);
    double largest = size_of(0, x, u);
    double previous = largest;
    for (int r = 0; r < K; ++r) {
      const double f = st.eta_ / (r + 1);
      for (std::size_t g = 0; g < groups; ++g) {
        // d^r/dt^r of sin and cos at ωt, scaled by (ωη)^r / r!.
        harmonic_derivative(r, load_sin_[g], load_cos_[g], load_ds_[g], load_dc_[g]);
        load_ds_[g] *= load_scale_[g];
        load_dc_[g] *= load_scale_[g];
        load_scale_[g] *= st.loads_[g].omega * st.eta_ / (r + 1);
      }
      const Index from = first_row(r + 1), to = last_row(r + 1);
      const WindowRows xr{x, lo}, ur{u, lo};
      // The forces of the springs touching in the current mode (the offset in the first term).
      const auto force_of = [&](Index j) {
        if (!(st.mode_[j] > 0.0)) return 0.0;
        const double force = st.stiffnesses_[j] * st.spring_stretch(j, xr);
        return r == 0 ? force - st.spring_offset_[j] : force;
      };
      for (Index i = from; i < to; ++i) {
        const Index row = lo + i;
        double acc = st.row_acceleration(row, xr, ur, force_of);
        for (std::size_t g = 0; g < groups; ++g) {
          acc += load_ds_[g] * st.loads_[g].sin_part[row] + load_dc_[g] * st.loads_[g].cos_part[row];
        }
        x_next[i] = f * u[i];
        u_next[i] = f * acc;
      }
      std::swap(x, x_next);
      std::swap(u, u_next);
      record_gaps(r + 1, x);
      const double size = size_of(r + 1, x, u);
      largest = std::max(largest, size);
      if (r + 1 >= 4 && size + previous <= 0.5 * kEpsilon * largest) return r + 1;
      previous = size;
    }
    return -1;
  }

  int window_terms_ = 0;  // the windows' K; 0: max_series_terms
  std::vector<Index> screen_springs_;  // the springs the first screen left, ascending
  std::vector<std::size_t> window_springs_;  // those of one window (entries of screen_springs_)
  RowRanges screen_ranges_;            // their windows
  std::vector<double> screen_coefficients_;
  std::vector<double> window_x_, window_u_;  // two terms of the window's series
  std::vector<double> load_sin_, load_cos_, load_scale_, load_ds_, load_dc_;
  PolynomialGaps screen_poly_;
  event_detail::GapSample screen_start_;
  event_detail::SearchSettings screen_settings_;
  std::vector<Index> screen_flips_;
};

}  // namespace pwl::switching_detail
