#pragma once
// Safeguarded location of the first time a gap spring changes state (private to pwl_core).
//
// Between two switches a structure with gap springs moves in one linear "mode" (a fixed set of
// touching springs), and the gap functions of that mode are smooth and cheap to evaluate at any
// time: in closed form for the event-driven solver, as a polynomial inside one step for the
// high-order PIM. This file finds, given such a mode, the first time after a start at which a
// spring leaves the side its mode assumes, and it does so without stepping over a grazing
// contact (a touch-and-release that happens between two samples).
//
// The gap functions are used "mode-signed": e_j = s_j g_j with s_j = +1 for a touching spring
// and -1 for a slack one, so e_j > 0 means "spring j is where its mode says it is" and an event
// is e_j turning negative. Every spring has a tolerance tol_j: |e_j| <= tol_j counts as being on
// the kink (rounding level), so a spring that hovers at its kink does not raise a stream of
// events, and a crossing is only reported once e_j < -tol_j somewhere.
//
// The method (after Shampine & Thompson, "Event location for ordinary differential equations",
// Comput. Math. Appl. 39 (2000) 43-54, and Hairer, Nørsett & Wanner, Solving ODEs I, §II.6, made
// rigorous with a derivative bound in the spirit of interval root isolation):
//  - sample the gap functions and their rates at a spacing proposed from the samples;
//  - on each interval [a, b] of length h, with a bound B_j >= |e_j''| valid on [a, b] (the
//    smaller of the mode's global bound and (|e_j''(a)| + |e_j''(b)| + h max|e_j'''|) / 2), the
//    concave parabolas e_j(a) + e_j'(a) u - B_j u²/2 (from the left) and
//    e_j(b) - e_j'(b) w - B_j w²/2 (from the right) are lower bounds of e_j. If the regions where
//    they are positive cover [a, b], spring j certainly does not cross there, not even for an
//    instant. If e_j(b) < -tol_j and the rate bounds e_j'(a) + B_j u and e_j'(b) + B_j w show that
//    e_j' < 0 throughout, it crosses exactly once. Otherwise the interval is split at its middle
//    and both halves are examined, the left one first. A grazing contact therefore ends up in a
//    subinterval short enough for the bounds to see it, and the earliest crossing is the one
//    reported;
//  - each single crossing is refined by Newton's method safeguarded by bisection (the rate is
//    known) until the bracket is a few units in the last place wide; the event is placed just
//    past the crossing, where e_j <= 0.
// Intervals shorter than min_width are decided by the signs at their ends and counted as
// "uncertified" (a touch shorter than that cannot change the motion beyond rounding).
//
// A spring that has just switched sits on its kink with e_j = 0, where the bounds above cannot
// certify anything. The caller gives it a "certified_until" time from the leading derivatives
// of its gap in the new mode (see certify_departure); no interval straddles that time, and
// before it the spring is not examined.
#include <functional>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::event_detail {

// The mode-signed gaps, their rates and accelerations at one time. `carry` holds whatever the
// mode needs to continue from this sample or to bound derivatives after it (the augmented state
// of the exponential representation, the sizes of the modal terms).
struct GapSample {
  double t = 0.0;
  Vector e;
  Vector rate;
  Vector accel;
  Vector carry;
};

// One mode's gap functions, e_j(t) for t in the mode's interval.
class ModeGaps {
 public:
  virtual ~ModeGaps() = default;
  virtual Index springs() const = 0;
  // The sample at time t >= from.t, computed from `from` (a sample of the same mode).
  virtual void sample(const GapSample& from, double t, GapSample& out) = 0;
  // bound[j] >= |d^order e_j / dt^order| on [from.t, from.t + span].
  virtual void derivative_bound(const GapSample& from, double span, int order,
                                Vector& bound) = 0;
  // d(j, r) = d^r e_j / dt^r at `at`, r = 0..max_order.
  virtual void derivatives(const GapSample& at, int max_order, Matrix& d) = 0;
  // e_j and its rate at time t (for the root refinement of one spring); representations that
  // can do it cheaper than a whole sample override this and the two below.
  virtual void sample_spring(const GapSample& from, double t, Index spring, double* e,
                             double* rate) {
    sample(from, t, scratch_sample_);
    *e = scratch_sample_.e[spring];
    *rate = scratch_sample_.rate[spring];
  }
  // The same for one spring only (d[0..max_order]).
  virtual void spring_derivatives(const GapSample& at, Index spring, int max_order, double* d) {
    derivatives(at, max_order, scratch_derivatives_);
    for (int r = 0; r <= max_order; ++r) d[r] = scratch_derivatives_(spring, r);
  }
  virtual double spring_derivative_bound(const GapSample& from, double span, int order,
                                         Index spring) {
    derivative_bound(from, span, order, scratch_bound_);
    return scratch_bound_[spring];
  }

 private:
  Matrix scratch_derivatives_;
  Vector scratch_bound_;
  GapSample scratch_sample_;
};

struct SearchSettings {
  double nominal_spacing = 1.0;  // sample spacing when the envelopes allow no more
  double max_spacing = 0.0;      // 0: no cap; otherwise samples are at most this far apart
  double min_width = 0.0;        // narrower intervals are decided by their end signs
  Vector tolerance;              // tol_j
  Vector certified_until;        // spring j is not examined before this time
  // A work budget: once this many gap evaluations are spent the search stops where it has
  // certified that no spring crossed (SearchResult::stopped). 0: no limit.
  long max_samples = 0;
  // Called every kTickSamples gap evaluations with the time certified so far and the
  // evaluations spent (progress reports of a long search); may be empty. What it throws
  // leaves the search.
  std::function<void(double t, long samples)> tick;
  static constexpr long kTickSamples = 1024;
};

struct SearchResult {
  bool found = false;
  bool stopped = false;        // max_samples spent: `at` is the last certified sample
  GapSample at;                // just past the first crossing, or at t_end
  std::vector<Index> springs;  // the springs that cross at `at`
  long samples = 0;            // gap evaluations spent
  long uncertified = 0;        // intervals decided by end signs only
};

// The search and the departure test. An EventLocator keeps its work space between calls, so a
// stepper that looks for switches in many steps allocates nothing after the first.
class EventLocator {
 public:
  // Looks for the first crossing in (start.t, t_end]. A spring with e_j < -tol_j already at the
  // start is reported as crossing at the start. The result stays valid until the next call.
  const SearchResult& find_first_crossing(ModeGaps& gaps, const GapSample& start, double t_end,
                                          const SearchSettings& settings);

  // A spring that has just switched (on its kink at `at`, in its new mode): from the
  // derivatives of its mode-signed gap, the time for which it certainly stays on the side of its
  // new mode. Returns +1 with *until set when the spring is clearly on its side already
  // (e > tol; *until = at.t) or its first significant derivative is positive, -1 when that
  // derivative is negative (the new mode is the wrong one: the spring only touched its kink), 0
  // when no derivative up to the sixth is significant (it rests on its kink;
  // *until = at.t + min_width).
  //
  // The first derivatives of a gap at its kink do not depend on the spring's own mode (its force
  // vanishes there), but what counts as significant does: the bound of a derivative's size is
  // larger in the mode where the spring is slack and its degree of freedom moves freely. So a
  // derivative can be significant in one mode and below the threshold in the other, and each
  // mode then sends the spring to the other. The caller settles that by the lower order (the
  // event-driven solver's settle): `assumed_order` > 0 takes the derivative of that order as
  // significant when it points to this mode's side, the lower orders as rounding; `order`, when
  // not null, receives the order that decided (0: none did).
  int certify_departure(ModeGaps& gaps, const GapSample& at, Index spring, double tol,
                        double max_span, double min_width, double* until,
                        int assumed_order = 0, int* order = nullptr);

 private:
  enum class Verdict { none, single, unknown };
  bool examined(Index j, double t) const { return s_->certified_until[j] <= t; }
  void sample(const GapSample& from, double t, GapSample& out);
  double propose(const GapSample& a, double t_end);
  void classify(const GapSample& a, const GapSample& b, bool* unknown, bool* single);
  void refine(const GapSample& a, const GapSample& b, GapSample& best);
  double refine_one(Index j, const GapSample& a, double hi_t, double hi_e, double hi_r);
  GapSample& push();
  bool out_of_budget();

  ModeGaps* gaps_ = nullptr;
  const SearchSettings* s_ = nullptr;
  Index m_ = 0;
  SearchResult result_;
  Vector bound_, third_;
  std::vector<Verdict> verdict_;
  std::vector<bool> sign_only_;
  std::vector<GapSample> stack_;  // stack_[0..top_) are in use
  std::size_t top_ = 0;
  long next_tick_ = 0;
  GapSample a_;
};

}  // namespace pwl::event_detail
