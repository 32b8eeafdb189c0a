#include "event/event_location.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace pwl::event_detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
constexpr int kMaxRefinements = 200;
// Leading derivatives examined when a spring leaves its kink.
constexpr int kDepartureOrders = 6;
// A derivative counts as significant when it exceeds this fraction of the bound of its size
// (what is left after cancellation is a few units of rounding of that bound).
constexpr double kSignificance = 1e-9;

// How far the parabola e0 + r u - B u²/2 stays positive from u = 0: its positive root (0 when
// e0 <= 0, infinite when it never comes down). Each sign of r has its own cancellation-free
// form: (r + √(r² + 2 B e0)) / B for r >= 0, 2 e0 / (√(r² + 2 B e0) - r) for r < 0 (which
// also covers B = 0).
double reach(double e0, double r, double B) {
  if (!(e0 > 0.0)) return 0.0;
  const double root = std::sqrt(r * r + 2.0 * B * e0);
  if (r >= 0.0) return B > 0.0 ? (r + root) / B : kInfinity;
  return 2.0 * e0 / (root - r);
}

}  // namespace

void EventLocator::sample(const GapSample& from, double t, GapSample& out) {
  gaps_->sample(from, t, out);
  ++result_.samples;
}

// Ticks the caller's progress hook and reports whether the sample budget is spent.
bool EventLocator::out_of_budget() {
  if (s_->tick && result_.samples >= next_tick_) {
    next_tick_ = result_.samples + SearchSettings::kTickSamples;
    s_->tick(a_.t, result_.samples);
  }
  return s_->max_samples > 0 && result_.samples >= s_->max_samples;
}

GapSample& EventLocator::push() {
  if (top_ == stack_.size()) stack_.emplace_back();
  return stack_[top_++];
}

const SearchResult& EventLocator::find_first_crossing(ModeGaps& gaps, const GapSample& start,
                                                      double t_end,
                                                      const SearchSettings& settings) {
  gaps_ = &gaps;
  s_ = &settings;
  m_ = gaps.springs();
  bound_.resize(m_);
  third_.resize(m_);
  verdict_.assign(static_cast<std::size_t>(m_), Verdict::none);
  sign_only_.assign(static_cast<std::size_t>(m_), false);
  result_.found = false;
  result_.stopped = false;
  result_.springs.clear();
  result_.samples = 1;
  result_.uncertified = 0;
  top_ = 0;
  next_tick_ = SearchSettings::kTickSamples;

  for (Index j = 0; j < m_; ++j) {
    if (examined(j, start.t) && start.e[j] < -s_->tolerance[j]) result_.springs.push_back(j);
  }
  if (!result_.springs.empty() || start.t >= t_end) {
    result_.found = !result_.springs.empty();
    result_.at = start;
    return result_;
  }
  a_ = start;
  while (true) {
    top_ = 0;
    GapSample& first = push();
    sample(a_, propose(a_, t_end), first);
    while (top_ > 0) {
      if (out_of_budget()) {
        // a_ is certified: no spring crosses in (start.t, a_.t].
        result_.stopped = true;
        result_.at = a_;
        return result_;
      }
      GapSample& b = stack_[top_ - 1];
      const double width = b.t - a_.t;
      const double middle = a_.t + 0.5 * width;
      const bool divisible = width > s_->min_width && middle > a_.t && middle < b.t;
      bool unknown = false, single = false;
      classify(a_, b, &unknown, &single);
      if (unknown && divisible) {
        GapSample& mid = push();  // may move the stack; b is not used again
        sample(a_, middle, mid);
        continue;
      }
      if (unknown) {
        // Too narrow to split further: decide by the signs at the ends. A spring that gets here
        // hugs its kink (e ~ 0 over a stretch); for the rest of this search it is judged by its
        // signs alone, so that the search keeps moving.
        ++result_.uncertified;
        for (Index j = 0; j < m_; ++j) {
          auto& v = verdict_[static_cast<std::size_t>(j)];
          if (v == Verdict::unknown) {
            v = b.e[j] < -s_->tolerance[j] ? Verdict::single : Verdict::none;
            single = single || v == Verdict::single;
            sign_only_[static_cast<std::size_t>(j)] = true;
          }
        }
      }
      if (single) {
        result_.found = true;
        refine(a_, b, result_.at);
        for (Index j = 0; j < m_; ++j) {
          if (!examined(j, a_.t)) continue;
          const double e = result_.at.e[j];
          const bool candidate = verdict_[static_cast<std::size_t>(j)] == Verdict::single;
          if (e < -s_->tolerance[j] || (e <= 0.0 && (candidate || result_.at.rate[j] < 0.0))) {
            result_.springs.push_back(j);
          }
        }
        return result_;
      }
      std::swap(a_, b);
      --top_;
    }
    if (a_.t >= t_end) {
      std::swap(result_.at, a_);
      return result_;
    }
  }
}

// The next sample time: as far as the left envelopes certify, at least the nominal spacing,
// never past t_end or the end of a spring's certified departure.
double EventLocator::propose(const GapSample& a, double t_end) {
  gaps_->derivative_bound(a, s_->nominal_spacing, 2, bound_);
  double h = kInfinity;
  for (Index j = 0; j < m_; ++j) {
    if (!examined(j, a.t)) continue;
    h = std::min(h, reach(a.e[j] + s_->tolerance[j], a.rate[j], bound_[j]));
  }
  h = std::max(h, s_->nominal_spacing);
  if (s_->max_spacing > 0.0) h = std::min(h, s_->max_spacing);
  double b = std::min(a.t + h, t_end);
  for (Index j = 0; j < m_; ++j) {
    if (s_->certified_until[j] > a.t) b = std::min(b, s_->certified_until[j]);
  }
  return b;
}

void EventLocator::classify(const GapSample& a, const GapSample& b, bool* unknown, bool* single) {
  const double h = b.t - a.t;
  gaps_->derivative_bound(a, h, 2, bound_);
  gaps_->derivative_bound(a, h, 3, third_);
  for (Index j = 0; j < m_; ++j) {
    auto& v = verdict_[static_cast<std::size_t>(j)];
    v = Verdict::none;
    if (!examined(j, a.t)) continue;
    const double tol = s_->tolerance[j];
    // |e''| on [a, b]: the global bound, or the end values plus the growth the third derivative
    // allows (tight on short intervals).
    const double B = std::min(
        bound_[j], 0.5 * (std::abs(a.accel[j]) + std::abs(b.accel[j]) + third_[j] * h));
    const double ra = a.rate[j], rb = b.rate[j];
    if (sign_only_[static_cast<std::size_t>(j)]) {
      v = b.e[j] < -tol ? Verdict::single : Verdict::none;
    } else if (b.e[j] < -tol) {
      // The largest the rate can be anywhere on [a, b], from the two slopes and |e''| <= B.
      const double top = std::min({ra + B * h, rb + B * h, 0.5 * (ra + rb + B * h)});
      v = top < 0.0 ? Verdict::single : Verdict::unknown;
    } else {
      const double left = reach(a.e[j] + tol, ra, B);
      const double right = reach(b.e[j] + tol, -rb, B);
      v = left + right > h ? Verdict::none : Verdict::unknown;
    }
    *unknown = *unknown || v == Verdict::unknown;
    *single = *single || v == Verdict::single;
  }
}

// The earliest crossing among the springs judged "single" on [a, b], into `best`. Each of them
// is refined on its own, evaluating that spring alone (at the earliest crossing found so far, a
// spring still positive there crosses later and is passed over); the whole sample is taken once,
// at the earliest crossing. When a step throws thousands of springs over their kinks at once (a
// long chain far from its orbit) a whole sample per spring would make this quadratic in the
// springs.
void EventLocator::refine(const GapSample& a, const GapSample& b, GapSample& best) {
  double best_t = b.t;
  for (Index j = 0; j < m_; ++j) {
    if (verdict_[static_cast<std::size_t>(j)] != Verdict::single) continue;
    double e = b.e[j], r = b.rate[j];
    if (best_t != b.t) {
      gaps_->sample_spring(a, best_t, j, &e, &r);
      ++result_.samples;
    }
    if (e > 0.0) continue;  // crosses after the best so far
    if (a.e[j] <= 0.0) {    // already on the kink at a: the event is at a
      best = a;
      return;
    }
    best_t = refine_one(j, a, best_t, e, r);
  }
  if (best_t == b.t) {
    best = b;
  } else {
    sample(a, best_t, best);
  }
}

// Newton's method on e_j, safeguarded by bisection, on a bracket with e_j(lo) > 0 >= e_j(hi)
// (hi at hi_t, where e_j = hi_e with rate hi_r), evaluating spring j alone. Once the Newton
// correction is a few units in the last place, one evaluation just past the estimated root
// closes the bracket from the crossed side. Returns the bracket's crossed end.
double EventLocator::refine_one(Index j, const GapSample& a, double hi_t, double hi_e, double hi_r) {
  double lo_t = a.t, lo_e = a.e[j], lo_r = a.rate[j];
  double previous_step = kInfinity;
  for (int k = 0; k < kMaxRefinements; ++k) {
    const double scale = std::max({std::abs(lo_t), std::abs(hi_t), s_->nominal_spacing});
    const double ulp = kEpsilon * scale;
    if (hi_t - lo_t <= 4.0 * ulp || hi_e == 0.0) break;
    const bool from_lo = std::abs(lo_e) < std::abs(hi_e);
    const double near_t = from_lo ? lo_t : hi_t;
    const double near_e = from_lo ? lo_e : hi_e;
    const double near_r = from_lo ? lo_r : hi_r;
    const double step = near_r < 0.0 ? -near_e / near_r : kInfinity;
    double t;
    if (std::abs(step) <= 2.0 * ulp) {
      if (!from_lo) break;         // hi is within rounding of the root
      t = lo_t + step + 2.0 * ulp;  // just past the root
    } else {
      t = near_t + step;
      if (!(std::abs(step) < 0.5 * previous_step)) t = 0.5 * (lo_t + hi_t);
    }
    if (!(t > lo_t && t < hi_t)) t = 0.5 * (lo_t + hi_t);
    if (!(t > lo_t && t < hi_t)) break;
    previous_step = std::abs(t - near_t);
    double e = 0.0, r = 0.0;
    gaps_->sample_spring(a, t, j, &e, &r);
    ++result_.samples;
    if (e > 0.0) {
      lo_t = t, lo_e = e, lo_r = r;
    } else {
      hi_t = t, hi_e = e, hi_r = r;
    }
  }
  return hi_t;
}

int EventLocator::certify_departure(ModeGaps& gaps, const GapSample& at, Index spring,
                                    double tol, double max_span, double min_width, double* until,
                                    int assumed_order, int* order) {
  if (order != nullptr) *order = 0;
  if (at.e[spring] > tol) {
    *until = at.t;
    return 1;
  }
  double d[kDepartureOrders + 1];
  gaps.spring_derivatives(at, spring, kDepartureOrders, d);
  for (int r = std::max(assumed_order, 1); r <= kDepartureOrders; ++r) {
    const double value = d[r];
    // The assumed order is significant when it points to this side; otherwise it and the
    // orders above it are judged against the bound of their size.
    if (r != assumed_order || !(value > 0.0)) {
      const double size = gaps.spring_derivative_bound(at, 0.0, r, spring);
      if (!(std::abs(value) > kSignificance * size)) continue;
    }
    if (order != nullptr) *order = r;
    if (value < 0.0) return -1;
    // e(u) >= d_r u^r / r! - B u^(r+1) / (r+1)! (the lower derivatives are rounding): positive,
    // with half of the leading term to spare, for u <= (r+1) d_r / (2 B).
    const double B = gaps.spring_derivative_bound(at, max_span, r + 1, spring);
    double span = B > 0.0 ? (r + 1) * value / (2.0 * B) : max_span;
    span = std::clamp(span, min_width, max_span);
    *until = at.t + span;
    return 1;
  }
  *until = at.t + min_width;
  return 0;
}

}  // namespace pwl::event_detail
