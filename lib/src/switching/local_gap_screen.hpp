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
// the whole state when the window is its rows widened by K · reach. The stepper's window_series
// computes term r on the window's rows at least r · reach from an edge that is not an end of the
// structure, with the whole state's banded stencils restricted to those rows (O(window) per
// term). K starts at max_series_terms and follows the screens' series down to 4 terms more than
// they need (one less per screen); a series that needs more than K sends its step to the
// switching path and puts K back to max_series_terms. The series of all the windows stops
// together, as the whole state's does, once two consecutive terms are below ε/2 of the largest,
// measured on the rows computed for them: a stopping rule of the same kind as the whole
// state's, not a bound. The finite reach of each term is what makes banded exponentials of
// chains possible in the first place (He, Gao & Zhong, Appl. Math. Mech. 39(7) (2018) 737-749);
// the screen itself is the polynomial root exclusion of event_location.hpp on the gap's series.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "event/event_location.hpp"
#include "pwl/types.hpp"
#include "switching/local_switch_correction.hpp"
#include "switching/switching_pim_detail.hpp"

namespace pwl::switching_detail {

// CRTP mixin of the banded switching stepper (a friend of it, whose ModeSeries buffers and search
// it uses): the stepper provides reach_, n_, m_, o_, signs_, gaps_, spring_span, spring_stretch,
// window_series (the Taylor series on windows of rows) and the first screen's terms.
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
      const auto [lo, hi] = st.spring_span(j);
      if (lo >= hi) return false;  // a spring without rows: nothing to window
      screen_springs_.push_back(j);
      screen_ranges_.add(std::max<Index>(0, lo - margin), std::min(st.n_, hi + margin));
    }
    if (screen_springs_.empty()) return true;
    screen_ranges_.normalize();
    if (4 * screen_ranges_.rows() >= st.n_) return false;

    const auto count = static_cast<Index>(screen_springs_.size());
    const auto stride = static_cast<std::size_t>(K + 1);
    screen_coefficients_.assign(static_cast<std::size_t>(count) * stride, 0.0);
    // The screened springs lie in their windows' middles: exact up to term K.
    double largest = 0.0;
    const int longest = st.window_series(t, screen_ranges_, K, 0.0, false, &largest,
                                         [&](int r, const Vector& x) {
                                           for (std::size_t i = 0; i < screen_springs_.size(); ++i) {
                                             screen_coefficients_[i * stride + static_cast<std::size_t>(r)] =
                                                 st.spring_stretch(screen_springs_[i], x);
                                           }
                                         });
    if (longest < 0) {
      window_terms_ = 0;
      return false;
    }
    window_terms_ = std::max(longest + 4, K - 1);

    // The polynomials of the screened springs, mode-signed, and the switching step's search on
    // them: settled kinks first, then a first crossing on [0, 1].
    screen_poly_.c.resize(count, longest + 1);
    for (Index k = 0; k < count; ++k) {
      const Index j = screen_springs_[static_cast<std::size_t>(k)];
      const double* c = &screen_coefficients_[static_cast<std::size_t>(k) * stride];
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
  int window_terms_ = 0;  // the windows' K; 0: max_series_terms
  std::vector<Index> screen_springs_;  // the springs the first screen left, ascending
  RowRanges screen_ranges_;            // their windows
  std::vector<double> screen_coefficients_;
  PolynomialGaps screen_poly_;
  event_detail::GapSample screen_start_;
  event_detail::SearchSettings screen_settings_;
  std::vector<Index> screen_flips_;
};

}  // namespace pwl::switching_detail
