#pragma once
// The continuation core: pseudo-arclength continuation of the solution curve of a defining system
// G(u) = 0, m equations in m + 1 unknowns, knowing nothing of the problem the system poses. Every
// continuation of pwl is a defining system on this one core: the periodic orbit followed in one
// parameter (continuation.hpp: the orbit's equations φ_kT(y; p) − y = 0 in (y, p)) and the
// bifurcation curves followed in two (bifurcation_curves.hpp: the orbit's equations plus the
// condition of a fold, a period doubling, a Neimark–Sacker point or a grazing, in (y, p, q) and an
// auxiliary unknown). The problems add themselves on top, as the continuation problems of COCO do
// (H. Dankowicz and F. Schilder, Recipes for Continuation, SIAM 2013).
//
// The method (H. B. Keller, in Applications of Bifurcation Theory, Academic Press 1977, 359-384;
// E. L. Allgower and K. Georg, Introduction to Numerical Continuation Methods, SIAM 2003, ch. 2):
// a step predicts along the unit tangent τ of the curve, u + h τ, and corrects by Newton on
// G(u) = 0 with τ · (u − prediction) = 0, whose bordered Jacobian [∂G/∂u; τ^T] is regular at a
// turning point of the curve. The corrector is Newton (the Jacobian formed at every iterate) or the
// Newton-chord method (Y. A. Kuznetsov, Elements of Applied Bifurcation Theory, 3rd ed., Springer
// 2004, §10.2.2): the Jacobian of a point nearby is kept while the residual falls at least
// fourfold a step, and formed afresh only where it does not, so that an accepted point costs
// about one Jacobian (at the point, where the problem wants it anyway) and a few evaluations of
// G. The step grows after easy corrections (Newton: two iterations or fewer; chord: the corrected
// point within 2e-4 of the prediction, relative to the state) and shrinks after hard ones, after
// a failed correction, a turn of the tangent by more than 30°, or where the problem finds that
// something it watches moved too far in one step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "pwl/types.hpp"

namespace pwl::orbits {

enum class Corrector { automatic, chord, newton };
// "automatic", "chord", "newton"; parse_corrector throws InputError naming the value for any
// other text.
std::string corrector_name(Corrector corrector);
Corrector parse_corrector(const std::string& name);

// m equations G(u) = 0 in m + 1 unknowns u. The first state_size() unknowns are a state (residuals
// and corrections are measured against its size), the others parameters and auxiliary unknowns.
class DefiningSystem {
 public:
  virtual ~DefiningSystem() = default;
  virtual Index state_size() const = 0;
  // G(u), and with `jacobian` also ∂G/∂u (m × (m + 1)) at u. False where G cannot be evaluated
  // (the motion blows up); the corrector then gives up, and the step is shortened.
  virtual bool evaluate(const Vector& u, Vector& G, Matrix* jacobian) = 0;
  // Whether u lies in the problem's domain (every parameter a value its model takes).
  virtual bool admissible(const Vector& u) const = 0;
  // The size residuals and corrections are measured against: max(1, |state|∞).
  double scale(const Vector& u) const {
    return std::max(1.0, u.head(state_size()).lpNorm<Eigen::Infinity>());
  }
};

struct CorrectorSettings {
  bool chord = false;        // chord steps on a kept Jacobian, or Newton
  int corrections = 7;       // Jacobians one correction may form before it converges
  double tolerance = 1e-10;  // |G|∞ <= tolerance · scale
  // Below `tolerance`: close further, to `polish`, or past the tolerance while each step shrinks
  // the residual fourfold (to the rounding floor, or until a chord step contracts more slowly);
  // the best iterate within the tolerance is returned where polishing ends on a worse one or runs
  // out of Jacobians or steps. 0: no polishing.
  double polish = 0.0;
  // Form the Jacobian at the solution (the problem wants it there: the monodromy for the
  // multipliers, the tangent). Without it the chord corrector returns without forming one.
  bool jacobian_at_solution = true;
};

struct CorrectedPoint {
  Vector u;
  Matrix jacobian;  // ∂G/∂u at u; empty where it was not formed there
  double residual = 0.0;  // |G(u)|∞
  int iterations = 0;
  int formed = 0;  // Jacobians formed before convergence
};

// Solves G(u) = 0 with τ · (u − prediction) = 0 from `guess`. `start` is the Jacobian the chord
// corrector starts from (that of a point nearby; ignored by Newton); without it the first is
// formed at the guess. Empty when the correction does not converge within the settings' Jacobians
// and steps, G cannot be evaluated, or u leaves the system's domain. `stalls` (optional) counts
// the chord steps that stalled, after which a Jacobian was formed again.
std::optional<CorrectedPoint> correct_on_curve(DefiningSystem& system, const Vector& guess,
                                               const Vector& prediction, const Vector& tau,
                                               const Matrix* start,
                                               const CorrectorSettings& settings,
                                               long* stalls = nullptr);

// The bordered Jacobian [J; row^T] ((m + 1) × (m + 1)).
Matrix bordered_jacobian(const Matrix& jacobian, const Vector& row);

// The unit tangent of the curve at a point whose Jacobian is J, oriented like `previous`:
// [J; previous^T] z = e_{m+1}.
Vector curve_tangent(const Matrix& jacobian, const Vector& previous);

// The step's length along the curve: its bounds and how it follows the corrector.
struct StepControl {
  double initial = 0.0;
  double min = 0.0;
  // The largest step, as a change of the parameters: the arclength step is at most this divided
  // by the parameters' share of the tangent (up to 100 times this), so that a curve whose state
  // moves fast is not crawled along.
  double max = 0.0;
  bool chord = false;
  // A walk that accepts this many steps in a row no longer than 16 times the minimum is stalled
  // (a curve that is not smooth there, which the corrector crosses only at the smallest steps, if
  // at all): it ends. 0: never.
  int stall_steps = 0;

  // The predictor's error (∞-norm, relative to the state's scale) below which the chord
  // corrector's step grows by 1.5 and above which it shrinks by 0.6. On the 100-mass chain of
  // `pwl bench orbits` this covers θ from 1 to 3 in 199 points, where Newton's rule took 200
  // points to reach 2.04, with the same grazings; 2e-5 and 2e-4 took 200 points to reach 1.43.
  static constexpr double kGrowBelow = 2e-4;
  static constexpr double kShrinkAbove = 2e-3;

  // The step after an accepted one of length h: Newton's grows after a corrector of two
  // iterations or fewer and shrinks after five or more; the chord corrector converges linearly,
  // at a rate set by how far the Jacobian moved since the last point, so its iterations say little
  // about the step, which follows the predictor's error instead (it grows like h² with the curve's
  // curvature). `parameter_share`: the parameters' part of the new point's unit tangent.
  double next(double h, double predictor_error, int iterations, double parameter_share) const {
    const double largest = max * std::min(1.0 / std::max(parameter_share, 1e-12), 100.0);
    const bool easy = chord ? predictor_error < kGrowBelow : iterations <= 2;
    const bool hard = chord ? predictor_error > kShrinkAbove : iterations >= 5;
    if (easy) h = std::min(1.5 * h, largest);
    h = std::min(h, largest);
    if (hard) h *= 0.6;
    return h;
  }
};

// The settings every walk along a curve takes from its options, checked once for all of them:
// the steps >= 0 and finite (0: the problem's default), at least 2 points and 2 corrections, a
// positive finite tolerance for locating zeros. False with *why naming the setting and its value.
bool walk_settings_valid(double initial_step, double min_step, double max_step, int max_points,
                         int max_corrections, double locate_tolerance, std::string* why);

// A point of a curve as the walk below handles it; problems derive their points from it.
struct CurvePoint {
  Vector u;
  Vector tangent;  // unit, oriented along the curve
  double residual = 0.0;
  int iterations = 0;
};

// A zero of a test function between two points of a curve, found by the Illinois variant of
// regula falsi on the arclength: the point nearest it, its value, and the final bracket's two
// points in the order of the arclength.
template <class P>
struct ArclengthZero {
  P best;
  double value = 0.0;
  bool located = false;  // the ends' values had opposite signs and every trial point was found
  P before, after;
};

// Locates the zero of a test function between a (arclength 0, value fa) and b (arclength h, value
// fb). `trial(s, end_a, sa, end_b, sb)` returns the curve's point at arclength s (corrected onto
// the curve, predicted by interpolating the bracket's ends) with its test value, or empty where it
// fails; `small(end_a, sa, end_b, sb)` says when the bracket is small enough. At most 80 trials,
// and none once the bracket is below 1e-13 of h.
template <class P, class Trial, class Small>
ArclengthZero<P> zero_on_arclength(const P& a, double fa, const P& b, double fb, double h,
                                   Trial trial, Small small) {
  const auto fabs_less = [](double x, double y) {
    if (!std::isfinite(y)) return true;
    if (!std::isfinite(x)) return false;
    return std::abs(x) < std::abs(y);
  };
  ArclengthZero<P> out;
  out.best = fabs_less(fa, fb) ? a : b;
  out.value = fabs_less(fa, fb) ? fa : fb;
  P end_a = a, end_b = b;  // the bracket's ends, at sa and sb
  double sa = 0, sb = h;
  out.located = std::isfinite(fa) && std::isfinite(fb) && fa * fb <= 0;
  int side = 0;  // Illinois: which end was kept last
  for (int it = 0; out.located && it < 80; ++it) {
    if (small(end_a, sa, end_b, sb)) break;
    if (std::abs(sb - sa) <= 1e-13 * std::abs(h)) break;
    double s = sb - fb * (sb - sa) / (fb - fa);
    if (!(s > std::min(sa, sb) && s < std::max(sa, sb))) s = 0.5 * (sa + sb);
    std::optional<std::pair<P, double>> found = trial(s, end_a, sa, end_b, sb);
    if (!found || !std::isfinite(found->second)) {
      out.located = false;
      break;
    }
    const double f = found->second;
    if (std::abs(f) < std::abs(out.value)) {
      out.best = found->first;
      out.value = f;
    }
    if (f * fb < 0) {
      sa = sb, fa = fb;
      end_a = std::move(end_b);
      side = 0;
    } else {
      if (side == 1) fa /= 2;  // Illinois
      side = 1;
    }
    sb = s, fb = f;
    end_b = std::move(found->first);
    if (f == 0) break;
  }
  if (sa <= sb) {
    out.before = std::move(end_a), out.after = std::move(end_b);
  } else {
    out.before = std::move(end_b), out.after = std::move(end_a);
  }
  return out;
}

// Why a walk along a curve ended.
struct WalkEnd {
  enum class Kind {
    max_points,  // it accepted its largest number of points
    min_step,    // the step fell below its minimum: no solution found ahead
    turns_back,  // the curve turns back on itself even at the smallest step
    stalled,     // StepControl::stall_steps steps in a row at the smallest steps
    problem,     // the problem stopped it (`why` says why)
  };
  Kind kind = Kind::problem;
  std::string why;
  int points = 0;  // accepted, the first included
};

// What a walk along a curve asks of its problem. P derives from CurvePoint.
template <class P>
class CurveWalk {
 public:
  virtual ~CurveWalk() = default;
  // The point corrected from the prediction `predicted` (h along from's tangent), completed with
  // whatever the problem keeps (its Jacobian, multipliers) and its tangent oriented like from's;
  // empty when the correction fails.
  virtual std::optional<P> corrected(const P& from, const Vector& predicted) = 0;
  // Why the walk stops at the step from `from` to `to` before accepting `to` (it rejoins another
  // curve, closes on itself), or empty.
  virtual std::optional<std::string> stop_before(const P& /*from*/, P& /*to*/, double /*h*/,
                                                 int /*points*/) {
    return std::nullopt;
  }
  // Whether the step from `from` to `to` moved something the problem watches further than one
  // step may (a Floquet multiplier near the unit circle, which could have left it and come back
  // unseen): the step is halved, as after a sharp turn of the tangent, down to four times the
  // smallest step, and the step after the point then accepted does not grow past it.
  virtual bool too_long(const P& /*from*/, const P& /*to*/) { return false; }
  // Accepts `to`, the walk's point number `points`: the events between the two points, the
  // output. A reason returned stops the walk there, `to` not kept as the walk's last point.
  virtual std::optional<std::string> accept(P& from, P& to, double h, int points) = 0;
  // Why the walk stops after accepting `point` (it left the range), or empty.
  virtual std::optional<std::string> stop_after(const P& /*point*/, int /*points*/) {
    return std::nullopt;
  }
  // The parameters' share of a unit tangent (for the step's largest length).
  virtual double parameter_share(const Vector& tangent) const = 0;
  // The size of a point's state (the unknowns before the parameters).
  virtual Index state_size() const = 0;

  // Walks from `first` (accepted already, its tangent set) until a hook stops it, the step falls
  // below its minimum, the curve turns back on itself even at the smallest step, or `max_points`
  // points are accepted (`first` counts). `last` (optional) receives the last point accepted.
  WalkEnd walk(P first, const StepControl& steps, int max_points, P* last = nullptr) {
    P current = std::move(first);
    double h = steps.initial;
    int points = 1;
    int crawling = 0;  // accepted steps in a row at the smallest steps
    bool held = false;  // the problem cut this step: the next does not grow past it
    Vector previous_secant;
    const auto end = [&](WalkEnd::Kind kind, std::string why) {
      if (last != nullptr) *last = current;
      return WalkEnd{kind, std::move(why), points};
    };
    while (true) {
      if (points >= max_points) return end(WalkEnd::Kind::max_points, "");
      if (h < steps.min) return end(WalkEnd::Kind::min_step, "");
      const Vector prediction = current.u + h * current.tangent;
      std::optional<P> next = corrected(current, prediction);
      if (!next) {
        h /= 2;
        continue;
      }
      if (next->tangent.dot(current.tangent) < std::cos(30.0 * kPi / 180) && h > 4 * steps.min) {
        h /= 2;
        continue;
      }
      if (h > 4 * steps.min && too_long(current, *next)) {
        h /= 2;
        held = true;
        continue;
      }
      // A step that turns back on the previous one (the secants at more than 90°) has gone back
      // along the curve, which happens at a sharp (non-smooth) turning point: shorter steps.
      const Vector secant = next->u - current.u;
      if (previous_secant.size() == secant.size() && secant.dot(previous_secant) < 0) {
        if (h > 4 * steps.min) {
          h /= 2;
          continue;
        }
        return end(WalkEnd::Kind::turns_back, "");
      }
      previous_secant = secant;
      if (auto why = stop_before(current, *next, h, points)) {
        return end(WalkEnd::Kind::problem, std::move(*why));
      }
      ++points;
      // The predictor's error: how far the corrector moved the prediction, relative to the state.
      const double predictor_error =
          (next->u - prediction).template lpNorm<Eigen::Infinity>() /
          std::max(1.0, next->u.head(state_size()).template lpNorm<Eigen::Infinity>());
      const int iterations = next->iterations;
      if (auto why = accept(current, *next, h, points)) {
        return end(WalkEnd::Kind::problem, std::move(*why));
      }
      current = std::move(*next);
      if (auto why = stop_after(current, points)) return end(WalkEnd::Kind::problem, *why);
      crawling = h <= 16 * steps.min ? crawling + 1 : 0;
      if (steps.stall_steps > 0 && crawling >= steps.stall_steps) {
        return end(WalkEnd::Kind::stalled, "");
      }
      const double grown =
          steps.next(h, predictor_error, iterations, parameter_share(current.tangent));
      h = held ? std::min(h, grown) : grown;
      held = false;
    }
  }

 private:
  static constexpr double kPi = 3.141592653589793;
};

}  // namespace pwl::orbits
