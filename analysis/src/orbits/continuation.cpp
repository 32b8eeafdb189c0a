#include "pwl/orbits/continuation.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <deque>
#include <fmt/format.h>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "orbits/bordered_krylov.hpp"
#include "orbits/leading_multipliers.hpp"
#include "orbits/multiplier_movement.hpp"
#include "orbits/newton_krylov.hpp"
#include "orbits/open_structure_preconditioner.hpp"

namespace pwl::orbits {

std::string bifurcation_name(BifurcationType type) {
  switch (type) {
    case BifurcationType::fold: return "fold";
    case BifurcationType::period_doubling: return "period-doubling";
    case BifurcationType::neimark_sacker: return "neimark-sacker";
    case BifurcationType::grazing: return "grazing";
  }
  return "?";
}

bool ContinuationOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!std::isfinite(start) || !std::isfinite(end) || start == end) {
    *why = fmt::format("range {}:{} must be two different finite values", start, end);
    return false;
  }
  if (!walk_settings_valid(initial_step, min_step, max_step, max_points, max_corrections,
                           locate_tolerance, why)) {
    return false;
  }
  if (!(band >= 0 && band < 1)) {
    *why = fmt::format("band = {} must be in [0, 1)", band);
    return false;
  }
  if (max_branches < 0) {
    *why = fmt::format("max branches = {} must be >= 0", max_branches);
    return false;
  }
  if (profile_samples < 8) {
    *why = fmt::format("profile samples = {} must be >= 8", profile_samples);
    return false;
  }
  if (method_traits(method.method).fixed_grid && steps_per_period < 1) {
    *why = fmt::format("steps per period = {} must be >= 1", steps_per_period);
    return false;
  }
  if (shooting.shots != 1) {
    *why = fmt::format("shots = {}: continuation uses single shooting", shooting.shots);
    return false;
  }
  if (shooting.solver == ShootingSolver::krylov && corrector == Corrector::chord) {
    *why = "corrector = chord: the matrix-free continuation (solver = krylov) corrects by "
           "Newton-Krylov on the bordered system; use corrector = newton or automatic";
    return false;
  }
  return shooting.is_valid(why);
}

namespace {

constexpr double kRealTolerance = 1e-9;  // |Im μ| below this (relative) counts as real

bool is_real(const std::complex<double>& mu) {
  return std::abs(mu.imag()) <= kRealTolerance * std::max(1.0, std::abs(mu));
}

// What the multipliers say about stability, by kind.
struct Signature {
  int real_above_one = 0;     // real μ > 1
  int real_below_minus_one = 0;
  int complex_outside = 0;    // complex μ with |μ| > 1
  int outside = 0;            // all with |μ| > 1
  bool operator==(const Signature&) const = default;
};

Signature signature(const FloquetMultipliers& mu) {
  Signature s;
  for (const auto& m : mu.values) {
    if (std::abs(m) > 1) ++s.outside;
    if (is_real(m)) {
      if (m.real() > 1) ++s.real_above_one;
      if (m.real() < -1) ++s.real_below_minus_one;
    } else if (std::abs(m) > 1) {
      ++s.complex_outside;
    }
  }
  return s;
}

// The test functions of each kind of bifurcation at one point (NaN: none of that kind there).
double nearest_real(const FloquetMultipliers& mu, double target) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const auto& m : mu.values) {
    if (!is_real(m)) continue;
    if (std::isnan(best) || std::abs(m.real() - target) < std::abs(best - target)) best = m.real();
  }
  return best;
}

std::complex<double> nearest_complex_to_circle(const FloquetMultipliers& mu) {
  std::complex<double> best{std::numeric_limits<double>::quiet_NaN(), 0};
  for (const auto& m : mu.values) {
    if (is_real(m)) continue;
    if (std::isnan(best.real()) || std::abs(std::abs(m) - 1) < std::abs(std::abs(best) - 1)) {
      best = m;
    }
  }
  if (best.imag() < 0) best = std::conj(best);
  return best;
}

// A point of the branch: u = (y, p), and what was computed there.
struct Point : CurvePoint {
  Matrix M;  // monodromy (empty where the corrector did not form it at the point)
  FloquetMultipliers mu;
  Eigen::MatrixXcd ritz;  // matrix-free: the leading multipliers' Ritz vectors (column i: mu[i])
  Vector b;  // ∂F/∂p
  std::optional<OrbitProfile> profile;
  int formed = 0;  // monodromies the corrector formed before it converged

  Index n() const { return u.size() - 1; }
  auto y() const { return u.head(u.size() - 1); }
  double p() const { return u(u.size() - 1); }
};

// ∂F/∂(y, p) of F = φ(y; p) − y: [M − I, b].
Matrix orbit_jacobian(const Matrix& M, const Vector& b) {
  const Index N = M.rows();
  Matrix J(N, N + 1);
  J.leftCols(N) = M - Matrix::Identity(N, N);
  J.col(N) = b;
  return J;
}

// Corrector::automatic takes the chord corrector above this many state components.
constexpr Index kChordAbove = 20;
// A bifurcation's trial points are closed to this residual (relative, as the shooting tolerance)
// where the corrector gets there: past the shooting tolerance it goes on while each step shrinks
// the residual fourfold (so it stops at the rounding floor, or where a chord step contracts
// more slowly), keeping the best iterate within the tolerance. An orbit closed to a residual r
// places a test function to about r over its slope, and a gap's extreme can change slowly with
// the parameter: on the 100-mass chain of `pwl bench orbits` beyond θ = 2.6, grazings located on
// orbits closed to 1e-10 were off by up to 8.9e-8, and on orbits closed to 1e-12 they agreed
// between the two correctors to 1e-9.
constexpr double kLocateResidual = 1e-12;
// Matrix-free, the multipliers of those trial points are asked for to this relative residual
// (accepted at the shooting's own, ArnoldiOptions::tolerance, where they stop short of it): a
// test function |μ| − 1 of a long chain's long wave changes by about 5e-5 per unit of θ (the
// 1000-mass chain's first Neimark–Sacker point), so Ritz values to 1e-10 placed it only to about
// 2e-8, from run to run.
constexpr double kLocateMultipliers = 1e-12;
// A real multiplier within this of +1 or -1 at both ends of a step is pinned there, not crossing.
constexpr double kPinned = 1e-6;
// A step whose multipliers' signature is not explained is cut in two at most this many times in
// a row (2^-30 of the step).
constexpr int kMaxCuts = 30;
// Matrix-free: GMRES's relative residual for a tangent of the branch (a direction for the
// predictor and the orientation of the next: a few digits suffice, ten cost little more).
constexpr double kTangentTolerance = 1e-10;

class Continuer {
 public:
  Continuer(const analysis::PointModel& model, const ContinuationOptions& options,
            ContinuationObserver* observer, ContinuationResult& result)
      : model_(model),
        recycled_(options.shooting.gmres_recycled, options.shooting.gmres_reform),
        options_(options),
        observer_(observer),
        result_(result) {
    const double range = std::abs(options.end - options.start);
    initial_step_ = options.initial_step > 0 ? options.initial_step : range / 100;
    min_step_ = options.min_step > 0 ? options.min_step : 1e-7 * range;
    max_step_ = options.max_step > 0 ? options.max_step : range / 25;
    lo_ = std::min(options.start, options.end);
    hi_ = std::max(options.start, options.end);
  }

  void run(const Vector& guess) {
    // The first point: Newton at fixed p = start.
    StroboscopicMap& map = map_at(options_.start);
    const int period = options_.shooting.period;
    matrix_free_ = !uses_dense_solver(map, options_.shooting);
    if (matrix_free_ && options_.corrector == Corrector::chord) {
      throw InputError(fmt::format(
          "corrector = chord: the {} state components are beyond the dense limit of {}, where "
          "continuation is matrix-free and corrects by Newton-Krylov; use corrector = newton or "
          "automatic",
          map.state_size(), options_.shooting.dense_state_limit));
    }
    result_.matrix_free = matrix_free_;
    // Matrix-free the margin asks the leading multipliers to cover a band that wide; dense, every
    // multiplier is known and the band is the one asked for.
    result_.band = matrix_free_ ? std::max(options_.band, options_.shooting.arnoldi.margin)
                                : options_.band;
    chord_ = !matrix_free_ &&
             (options_.corrector == Corrector::chord ||
              (options_.corrector == Corrector::automatic && map.state_size() > kChordAbove));
    result_.corrector = chord_ ? Corrector::chord : Corrector::newton;
    ShootingOptions shooting = options_.shooting;
    shooting.solver = matrix_free_ ? ShootingSolver::krylov : ShootingSolver::dense;
    shooting.multipliers = !matrix_free_;
    if (matrix_free_ && options_.shooting.precondition) {
      open_.emplace(map.structure(), period * map.forcing_period());
    }
    const PeriodicOrbit orbit = find_periodic_orbit(map, guess, shooting);
    const Index N = orbit.state.size();
    Point first;
    first.u.resize(N + 1);
    first.u << orbit.state, options_.start;
    first.residual = orbit.residual;
    first.iterations = orbit.iterations;
    result_.krylov_products += orbit.krylov_products;
    first.b = parameter_derivative(orbit.state, options_.start, period);
    // The first tangent: (M − I) z_y = −b z_p with z_p = 1, pointing toward `end`.
    Vector z(N + 1);
    if (matrix_free_) {
      leading_multipliers(first, period, nullptr);
      Vector x;
      double s = 0;
      bordered(first.y(), first.p(), period, first.b, Vector::Zero(N), 1.0)
          .solve(Vector::Zero(N), 1.0, x, s, kTangentTolerance, options_.shooting.gmres_dimension,
                 options_.shooting.gmres_restarts, &recycled_);
      z << x, s;
    } else {
      first.M = orbit.monodromy;
      first.mu = orbit.multipliers;
      Eigen::PartialPivLU<Matrix> lu(first.M - Matrix::Identity(N, N));
      z.head(N) = lu.solve(-first.b);
      z(N) = 1.0;
    }
    if (!z.allFinite()) {
      throw InputError(fmt::format(
          "the orbit at {} = {} has a multiplier at 1: start the continuation elsewhere",
          options_.parameter.name(), options_.start));
    }
    z /= z.norm();
    if ((options_.end - options_.start) * z(N) < 0) z = -z;
    first.tangent = z;
    follow(std::move(first), 0, options_.shooting.period, 0, kNone);
    while (!pending_.empty() && branches_ < options_.max_branches) {
      Pending next = std::move(pending_.front());
      pending_.pop_front();
      switch_branch(next);
    }
  }

 private:
  struct Pending {
    Point at;      // the period-doubling point on the period-k branch
    int period = 1;
    std::size_t bifurcation = 0;  // its index in result_.bifurcations
  };

  StroboscopicMap& map_at(double p) {
    auto it = maps_.find(p);
    if (it != maps_.end()) return it->second;
    if (maps_.size() > 8) maps_.clear();
    const analysis::PointModel model = model_.with(options_.parameter, p);
    return maps_.emplace(p, StroboscopicMap(model.point_case(), options_.method,
                                            options_.steps_per_period))
        .first->second;
  }

  Vector residual(const Vector& y, double p, int period, Matrix* M) {
    StroboscopicMap& map = map_at(p);
    if (M != nullptr) {
      ++result_.monodromies;
      return map.advance_with_jacobian(y, period, *M) - y;
    }
    ++result_.integrations;
    return map.advance(y, period) - y;
  }

  Vector parameter_derivative(const Vector& y, double p, int period) {
    const double delta = 1e-6 * std::max(1.0, std::abs(p));
    const Vector plus = residual(y, p + delta, period, nullptr);
    const Vector minus = residual(y, p - delta, period, nullptr);
    return (plus - minus) / (2 * delta);
  }

  // The orbit's equations F(y, p) = φ_kT(y; p) − y = 0 as a defining system of the core, in
  // u = (y, p): its Jacobian [M − I, b] keeps the column b = ∂F/∂p it is given (a chord in that
  // column: b comes from central differences, two integrations, at the accepted points), and the
  // last monodromy it formed is kept for the multipliers.
  class OrbitEquations : public DefiningSystem {
   public:
    OrbitEquations(Continuer& c, int period, const Vector& b) : c_(c), period_(period), b_(b) {}
    Index state_size() const override { return b_.size(); }
    bool evaluate(const Vector& u, Vector& G, Matrix* jacobian) override {
      const Index N = b_.size();
      const Vector y = u.head(N);
      try {
        if (jacobian != nullptr) {
          G = c_.residual(y, u(N), period_, &M_);
          *jacobian = orbit_jacobian(M_, b_);
        } else {
          G = c_.residual(y, u(N), period_, nullptr);
        }
      } catch (const Error&) {
        return false;
      }
      return true;
    }
    bool admissible(const Vector& u) const override {
      const double p = u(u.size() - 1);
      std::string why;
      return std::isfinite(p) && c_.model_.accepts(c_.options_.parameter, p, &why);
    }
    const Matrix& monodromy() const { return M_; }

   private:
    Continuer& c_;
    int period_;
    const Vector& b_;
    Matrix M_;
  };

  // The corrector from the prediction itself, from the point `from` (its monodromy for the chord
  // corrector, its Ritz vectors for a matrix-free one's Arnoldi).
  std::optional<Point> correct(const Vector& prediction, const Point& from, int period) {
    return correct_from(prediction, prediction, from.tangent, from.b, period, &from.M,
                        options_.max_corrections, true, 0.0, &from);
  }

  // The tangent at a corrected point, oriented like `previous`: [J; previousᵀ] z = e_{m+1}, by LU
  // on the monodromy or, matrix-free, by GMRES on the bordered system.
  Vector tangent_at(const Point& pt, const Vector& previous, int period) {
    if (!matrix_free_) return curve_tangent(orbit_jacobian(pt.M, pt.b), previous);
    const Index N = pt.n();
    Vector x;
    double s = 0;
    bordered(pt.y(), pt.p(), period, pt.b, previous.head(N), previous(N))
        .solve(Vector::Zero(N), 1.0, x, s, kTangentTolerance, options_.shooting.gmres_dimension,
               options_.shooting.gmres_restarts, &recycled_);
    Vector z(N + 1);
    z << x, s;
    z /= z.norm();
    return z.dot(previous) < 0 ? Vector(-z) : z;
  }

  // Matrix-free: the open structure's inverse for the map at p over `period` periods (its 2 x 2
  // blocks retimed where the forcing period moved), or null without one.
  const detail::OpenStructurePreconditioner* open_at(double p, int period) {
    if (!open_ || !open_->available()) return nullptr;
    const double tau = period * map_at(p).forcing_period();
    if (tau != open_->time()) open_->retime(tau);
    return &*open_;
  }

  // Matrix-free: the bordered system [M − I, b; cᵀ, d] at the orbit through y at p, its products
  // tangent integrations of the map from y (replayed after the first).
  detail::BorderedKrylov bordered(const Vector& y, double p, int period, const Vector& b,
                                  const Vector& c, double d) {
    StroboscopicMap& map = map_at(p);
    const detail::OpenStructurePreconditioner* open = open_at(p, period);
    recycled_.operator_changed();
    return detail::BorderedKrylov(
        [this, &map, y, period](const Vector& v) {
          Matrix t = v;
          map.advance(y, period, t);
          ++result_.krylov_products;
          return Vector(t.col(0));
        },
        open, b, c, d);
  }

  // Matrix-free: the leading multipliers of the orbit at pt and their Ritz vectors, by Davidson
  // or thick-restarted Arnoldi warm-started from `warm` (a point nearby): at least the options'
  // count, and every one in the band of the options' margin (continuation's default: every one
  // above 1 − 1e-5, kContinuationMargin). `locating` (a bifurcation's trial point): asked for to
  // kLocateMultipliers, accepted at the options' tolerance where they stop short of it; where they stop short with
  // their band not covered (the count doubles only once converged), asked again at the options'
  // tolerance from the Ritz vectors just found, so that the band is covered as at any point.
  void leading_multipliers(Point& pt, int period, const Eigen::MatrixXcd* warm,
                           bool locating = false) {
    StroboscopicMap& map = map_at(pt.p());
    const Vector y = pt.y();
    ArnoldiOptions arnoldi = options_.shooting.arnoldi;
    arnoldi.block = map.tangent_block();
    const auto product = [&](Matrix& v) {
      map.advance(y, period, v);
      result_.arnoldi_products += v.cols();
    };
    const detail::OpenStructurePreconditioner* open = open_at(pt.p(), period);
    if (locating) arnoldi.tolerance = std::min(arnoldi.tolerance, kLocateMultipliers);
    pt.mu = detail::leading_multipliers(product, y.size(), arnoldi, open, warm, &pt.ritz);
    const double tolerance = options_.shooting.arnoldi.tolerance;
    if (locating && !pt.mu.converged && pt.mu.residual <= tolerance) {
      const double smallest = 1.0 - detail::watched_band(pt.mu);
      if (pt.mu.complete || smallest <= 1.0 - arnoldi.margin) {
        pt.mu.converged = true;  // as asked for at the options' tolerance
        pt.mu.band_covered = true;
      } else {
        const Eigen::MatrixXcd found = pt.ritz;
        arnoldi.tolerance = tolerance;
        pt.mu = detail::leading_multipliers(product, y.size(), arnoldi, open, &found, &pt.ritz);
      }
    }
    if (pt.mu.method == FloquetMultipliers::Method::davidson) ++result_.davidson_points;
    if (pt.mu.method == FloquetMultipliers::Method::arnoldi) ++result_.arnoldi_points;
    if (!pt.mu.converged) ++result_.unconverged_multipliers;
    if (pt.mu.converged && !pt.mu.band_covered) ++result_.uncovered_bands;
  }

  // Matrix-free corrector: Newton–Krylov (newton_krylov.hpp: inexact Newton, its forcing and its
  // polishing) on F(y, p) = 0 with τ · (u − prediction) = 0 from `guess`, each step the bordered
  // system [M − I, b; τᵀ] δ = −(F, τ · (u − prediction)) solved by GMRES. One integration a step
  // (which records the tangent map the step's products replay).
  std::optional<Point> correct_matrix_free(const Vector& guess, const Vector& prediction,
                                           const Vector& tau, const Vector& b, int period,
                                           int iterations, bool multipliers, double polish,
                                           const Point* near) {
    const Index N = b.size();
    detail::NewtonKrylovSystem system;
    system.admissible = [&](const Vector& u) {
      std::string why;
      return model_.accepts(options_.parameter, u(N), &why);
    };
    system.scale = [&](const Vector& u) {
      return std::max(1.0, u.head(N).lpNorm<Eigen::Infinity>());
    };
    Vector F;  // at the last u evaluated, which the step starts from
    system.residual = [&](const Vector& u) -> std::optional<double> {
      try {
        F = residual(u.head(N), u(N), period, nullptr);
      } catch (const Error&) {
        return std::nullopt;
      }
      if (!F.allFinite()) return std::nullopt;
      return F.lpNorm<Eigen::Infinity>();
    };
    system.step = [&](const Vector& u, double arc, double eta) -> std::optional<Vector> {
      Vector dx;
      double ds = 0;
      bordered(u.head(N), u(N), period, b, tau.head(N), tau(N))
          .solve(-F, -arc, dx, ds, eta, options_.shooting.gmres_dimension,
                 options_.shooting.gmres_restarts, &recycled_);
      Vector delta(N + 1);
      delta << dx, ds;
      return delta;
    };
    const std::optional<detail::NewtonKrylovPoint> c = detail::newton_krylov(
        system, guess, prediction, tau, iterations, polish, options_.shooting.tolerance);
    std::optional<Point> best;
    if (c) {
      best.emplace();
      best->u = c->u;
      best->residual = c->residual;
      best->iterations = c->iterations;
    }
    if (!best) return std::nullopt;
    if (multipliers) {
      leading_multipliers(*best, period, near != nullptr ? &near->ritz : nullptr, polish > 0);
    }
    return best;
  }

  const OrbitProfile& profile_of(Point& pt, int period) {
    if (!pt.profile) {
      pt.profile = orbit_profile(map_at(pt.p()), pt.y(), period, options_.profile_samples);
    }
    return *pt.profile;
  }

  BranchPoint branch_point(Point& pt, int branch, int period, double arclength) {
    BranchPoint bp;
    bp.branch = branch;
    bp.parameter = pt.p();
    bp.arclength = arclength;
    bp.orbit.state = pt.y();
    bp.orbit.period = period;
    bp.orbit.forcing_period = map_at(pt.p()).forcing_period();
    bp.orbit.residual = pt.residual;
    bp.orbit.iterations = pt.iterations;
    bp.orbit.exact_tangent = map_at(pt.p()).exact_tangent();
    bp.orbit.solver = matrix_free_ ? ShootingSolver::krylov : ShootingSolver::dense;
    bp.orbit.multipliers = pt.mu;
    bp.profile = profile_of(pt, period);
    return bp;
  }

  void note(std::string message) {
    if (observer_ != nullptr) observer_->note(message);
    result_.notes.push_back(std::move(message));
  }

  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::set<int> unconverged_noted_;  // branches whose unconverged multipliers were noted

  // The walk of one branch on the core's loop: its corrector, the checks that end a switched
  // branch (it rejoins its parent, or closes on itself), the events between its points, and the
  // range.
  class BranchWalk : public CurveWalk<Point> {
   public:
    BranchWalk(Continuer& c, int branch, int period, int parent_period, std::size_t source,
               std::vector<Vector> first_orbit, double first_p)
        : c_(c),
          branch_(branch),
          period_(period),
          parent_period_(parent_period),
          source_(source),
          first_orbit_(std::move(first_orbit)),
          first_p_(first_p),
          label_(fmt::format("branch {} (period {})", branch, period)) {}

    const std::string& label() const { return label_; }

    std::optional<Point> corrected(const Point& from, const Vector& predicted) override {
      std::optional<Point> next = c_.correct(predicted, from, period_);
      if (!next) return std::nullopt;
      next->b = c_.parameter_derivative(next->y(), next->p(), period_);
      next->tangent = c_.tangent_at(*next, from.tangent, period_);
      return next;
    }

    std::optional<std::string> stop_before(const Point& from, Point& to, double h,
                                           int points) override {
      const std::string& name = c_.options_.parameter.name();
      // (Its own period doubling counts once the branch has gone some way: a loop of period-2k
      // orbits may come back to where it started, as the other half of the same orbits.)
      if (parent_period_ > 0 &&
          c_.rejoins(from, to, h, parent_period_, points > 10 ? kNone : source_, branch_)) {
        return fmt::format("{}: rejoined the period-{} branch at its period doubling near {} = "
                           "{:.10g} after {} points",
                           label_, parent_period_, name, to.p(), points);
      }
      if (parent_period_ > 0) {
        Vector Fk;
        try {
          Fk = c_.residual(to.y(), to.p(), parent_period_, nullptr);
        } catch (const Error&) {
          Fk = Vector::Constant(1, std::numeric_limits<double>::infinity());
        }
        if (Fk.lpNorm<Eigen::Infinity>() <= 1e3 * c_.options_.shooting.tolerance *
                                                 std::max(1.0, to.y().lpNorm<Eigen::Infinity>())) {
          return fmt::format("{}: rejoined the period-{} branch near {} = {:.10g} (a period "
                             "doubling of it) after {} points",
                             label_, parent_period_, name, from.p(), points);
        }
      }
      if (points > 10) {
        // Closed: back at the first orbit, as the same state or as the same orbit started j
        // periods later (a period-k orbit is k fixed points of the period-k map).
        const Index N = to.n();
        for (const Vector& start : first_orbit_) {
          Vector gap(N + 1);
          gap.head(N) = to.y() - start;
          gap(N) = to.p() - first_p_;
          if (gap.norm() < h) return fmt::format("{}: closed on itself after {} points", label_, points);
        }
      }
      return std::nullopt;
    }

    // With a band (ContinuationOptions::band > 0, widened to ArnoldiOptions::margin): a step
    // is cut when a multiplier within half the band of the circle at one end has no partner of
    // its own at the other (detail::band_stayed: within half the band in the plane, or in modulus
    // having turned by at most 0.02 rad). What it catches: a multiplier near the circle that goes
    // out and back (or in and out) within one step, the same signature at both ends, as long as
    // its modulus over the step does not swing by more than its distance from the circle at the
    // ends. What it does not: a multiplier farther than half the band from the circle at both
    // ends (two pairs that cross the circle in opposite directions within one step from outside
    // the band leave the signature as it was: a band wider than the multipliers' movement in a
    // step is the user's choice), and a step already at four times the smallest (the core stops
    // cutting there). Where only the leading multipliers are known, the band is narrowed to what
    // both ends cover (watched_band), so that a near multiplier's partner, if it moved less than
    // half the band, is among the other end's; not checked where either end did not converge.
    bool too_long(const Point& from, const Point& to) override {
      if (!(c_.options_.band > 0)) return false;
      double band = c_.result_.band;
      for (const Point* end : {&from, &to}) {
        if (!end->mu.converged) return false;
        band = std::min(band, detail::watched_band(end->mu));
      }
      if (!(band > 0)) return false;
      c_.result_.narrowest_band = std::min(c_.result_.narrowest_band, band);
      if (detail::band_stayed(from.mu.values, to.mu.values, band)) return false;
      ++c_.result_.band_cuts;
      return true;
    }

    std::optional<std::string> accept(Point& from, Point& to, double h, int points) override {
      arclength_ += h;
      c_.retracing_ = false;
      c_.detect(from, to, h, branch_, period_);
      if (c_.retracing_) {
        return fmt::format("{}: stopped at {} = {:.10g} after {} points: it meets a bifurcation "
                           "of its own again, so from here it retraces its orbits",
                           label_, c_.options_.parameter.name(), to.p(), points);
      }
      c_.emit(c_.branch_point(to, branch_, period_, arclength_));
      return std::nullopt;
    }

    std::optional<std::string> stop_after(const Point& point, int points) override {
      const double margin = 1e-9 * (c_.hi_ - c_.lo_);
      if (point.p() > c_.hi_ + margin || point.p() < c_.lo_ - margin) {
        return fmt::format("{}: left the range at {} = {:.10g} after {} points", label_,
                           c_.options_.parameter.name(), point.p(), points);
      }
      return std::nullopt;
    }

    double parameter_share(const Vector& tangent) const override {
      return std::abs(tangent(tangent.size() - 1));
    }
    Index state_size() const override { return first_orbit_.front().size(); }

   private:
    Continuer& c_;
    int branch_, period_, parent_period_;
    std::size_t source_;
    std::vector<Vector> first_orbit_;
    double first_p_;
    std::string label_;
    double arclength_ = 0.0;
  };

  // Follows one branch from its first point. A branch switched onto at a period doubling of a
  // period-`parent_period` branch stops where it rejoins that branch (its orbits become
  // period-`parent_period` ones: another period doubling of the parent) or closes on itself.
  void follow(Point first, int branch, int period, int parent_period, std::size_t source) {
    const double first_p = first.p();
    branch_start_ = first_p;
    std::vector<Vector> first_orbit{first.y()};
    for (int j = 1; j < period; ++j) {
      try {
        first_orbit.push_back(map_at(first_p).advance(first_orbit.back(), 1));
      } catch (const Error&) {
        break;
      }
    }
    emit(branch_point(first, branch, period, 0.0));
    BranchWalk walk(*this, branch, period, parent_period, source, std::move(first_orbit),
                    first_p);
    const StepControl steps{initial_step_, min_step_, max_step_, chord_};
    Point last;
    const WalkEnd end = walk.walk(std::move(first), steps, options_.max_points, &last);
    const std::string& name = options_.parameter.name();
    switch (end.kind) {
      case WalkEnd::Kind::max_points:
        note(fmt::format("{}: stopped after {} points (max points)", walk.label(), end.points));
        break;
      case WalkEnd::Kind::min_step:
        note(fmt::format("{}: stopped at {} = {:.10g}: the step fell below {:.3g} (no orbit "
                         "found ahead)",
                         walk.label(), name, last.p(), min_step_));
        break;
      case WalkEnd::Kind::turns_back:
        note(fmt::format("{}: stopped at {} = {:.10g} after {} points: the branch turns back "
                         "on itself there even at the smallest step",
                         walk.label(), name, last.p(), end.points));
        break;
      case WalkEnd::Kind::stalled:  // not asked for (StepControl::stall_steps is 0)
      case WalkEnd::Kind::problem: note(end.why); break;
    }
  }

  // Whether the step from a to b passes through a period doubling of the parent branch other than
  // the one the branch started from (then the branch goes on as the parent's orbits, or as the
  // other half of the same loop). That period doubling is marked as switched onto this branch.
  bool rejoins(const Point& a, const Point& b, double h, int parent_period, std::size_t source,
               int branch) {
    const Index N = a.n();
    const Vector ab = b.u - a.u;
    const double length2 = ab.squaredNorm();
    for (std::size_t i = 0; i < result_.bifurcations.size(); ++i) {
      Bifurcation& bif = result_.bifurcations[i];
      if (bif.type != BifurcationType::period_doubling || bif.period != parent_period ||
          i == source) {
        continue;
      }
      Vector ap(N + 1);
      ap.head(N) = bif.state - a.y();
      ap(N) = bif.parameter - a.p();
      const double w = length2 > 0 ? std::clamp(ap.dot(ab) / length2, 0.0, 1.0) : 0.0;
      const double distance = (ap - w * ab).norm();
      if (distance <= std::max(0.25 * h, 1e-7)) {
        bif.joined_by = branch;
        std::erase_if(pending_, [&](const Pending& p) { return p.bifurcation == i; });
        return true;
      }
    }
    return false;
  }

  void emit(const BranchPoint& bp) {
    if (observer_ != nullptr) observer_->point(bp);
    result_.points.push_back(bp);
  }

  // The bifurcations between two consecutive points a and b (b predicted from a with step h
  // along a's tangent), located and recorded: those the multipliers' signature shows
  // (explain_signature), then the grazings the orbits' profiles show.
  // They are recorded in their order along the branch.
  void detect(Point& a, Point& b, double h, int branch, int period) {
    step_found_.clear();
    if (a.mu.converged && b.mu.converged) {
      explain_signature(a, b, h, branch, period, 0);
    } else if (unconverged_noted_.insert(branch).second) {
      // Ritz values short of their tolerance can cross the circle with nothing crossing there:
      // a change of signature between them is not an event, and locating it would run Arnoldi
      // again at every trial point for nothing (the count of such points is in the result).
      note(fmt::format("on branch {} the leading multipliers did not converge from {} = {:.10g} "
                       "(Arnoldi short of its tolerance): no stability change is detected across "
                       "a step with such an end; grazings still are",
                       branch, options_.parameter.name(), a.mu.converged ? b.p() : a.p()));
    }
    if (options_.grazing) {
      const OrbitProfile& pa = profile_of(a, period);
      const OrbitProfile& pb = profile_of(b, period);
      for (Index j = 0; j < pa.max_gap.size(); ++j) {
        for (const int which : {static_cast<int>(2 * j), static_cast<int>(2 * j + 1)}) {
          const bool largest = which % 2 == 0;
          if (((largest ? pa.max_gap(j) : pa.min_gap(j)) > 0) ==
              ((largest ? pb.max_gap(j) : pb.min_gap(j)) > 0)) {
            continue;
          }
          step_found_.push_back({BifurcationType::grazing, which,
                                 locate(a, b, h, BifurcationType::grazing, which, period), a.p(),
                                 b.p()});
        }
      }
    }
    const auto along = [&](const Found& f) { return a.tangent.dot(f.where.best.u - a.u); };
    std::stable_sort(step_found_.begin(), step_found_.end(),
                     [&](const Found& x, const Found& y) { return along(x) < along(y); });
    for (const Found& f : step_found_) {
      if (retracing_) return;
      record(f.type, f.which, branch, period, f.where, f.from, f.to);
    }
  }

  // What changes in the multipliers' signature from a to b (multipliers outside the unit circle
  // by kind: real above +1, real below -1, complex pairs), as one event, none, or several.
  enum class Change { none, fold, period_doubling, neimark_sacker, several };
  Change change_between(const Point& a, const Point& b, int branch) const {
    const Signature sa = signature(a.mu), sb = signature(b.mu);
    const int plus = sb.real_above_one - sa.real_above_one;
    const int minus = sb.real_below_minus_one - sa.real_below_minus_one;
    const int pairs = (sb.complex_outside - sa.complex_outside) / 2;
    if (plus == 0 && minus == 0 && pairs == 0) return Change::none;
    // A complex pair outside the circle meeting the real axis there (two real multipliers beyond
    // +1 or below -1), or two such real multipliers splitting into a pair: no bifurcation.
    if (std::abs(pairs) == 1 && ((plus == -2 * pairs && minus == 0) ||
                                 (minus == -2 * pairs && plus == 0))) {
      return Change::none;
    }
    // A real multiplier that stays within kPinned of +1 or -1 at both points is not a
    // transversal crossing but a multiplier pinned there (the +1 of a period-2k branch at the
    // period doubling it starts from, or of a structure that is free to drift), wobbling by
    // rounding.
    const auto pinned = [&](double target) {
      const double at_a = nearest_real(a.mu, target), at_b = nearest_real(b.mu, target);
      return std::isfinite(at_a) && std::isfinite(at_b) &&
             std::max(std::abs(at_a - target), std::abs(at_b - target)) <= kPinned;
    };
    if (std::abs(plus) == 1 && minus == 0 && pairs == 0) {
      // A switched branch starts at a period doubling, where its own multiplier +1 is pinned: no
      // fold is taken within 1e-4 of the range from its start.
      const bool at_switch =
          branch > 0 && std::max(std::abs(a.p() - branch_start_),
                                 std::abs(b.p() - branch_start_)) <= 1e-4 * (hi_ - lo_);
      return pinned(1.0) || at_switch ? Change::none : Change::fold;
    }
    if (std::abs(minus) == 1 && plus == 0 && pairs == 0) {
      return pinned(-1.0) ? Change::none : Change::period_doubling;
    }
    if (std::abs(pairs) == 1 && plus == 0 && minus == 0) return Change::neimark_sacker;
    return Change::several;
  }

  static BifurcationType type_of(Change change) {
    switch (change) {
      case Change::fold: return BifurcationType::fold;
      case Change::period_doubling: return BifurcationType::period_doubling;
      default: return BifurcationType::neimark_sacker;
    }
  }

  // Every change of the multipliers' signature from a to b (b at arclength s along a's tangent)
  // explained by bifurcations located between them: one event (a fold changes the count beyond
  // +1 by one, a period doubling the count beyond -1, a Neimark–Sacker point the complex pairs
  // outside) is located, and kept when the ends of its final bracket show the whole change and
  // nothing else happens between them and a or b. Anything else (several events in the step, an
  // event whose location lands elsewhere, a test function that jumps where multipliers collide on
  // the real axis) cuts the step in two at half its arclength, the half point corrected onto the
  // branch with its own multipliers, and each half is explained in turn, until each event sits
  // alone in its interval. A grazing explains no change of signature: the map is C¹ there and
  // the multipliers pass through it continuously, however steeply (SPEC §8).
  void explain_signature(Point& a, Point& b, double s, int branch, int period, int depth) {
    const Change change = change_between(a, b, branch);
    if (change == Change::none) return;
    if (change != Change::several) {
      const BifurcationType type = type_of(change);
      const Located found = locate(a, b, s, type, -1, period);
      // The bracket's ends have a's and b's signatures: the one event accounts for the whole
      // change (compared as counts: the ends lie within the location's tolerance of the event,
      // where the crossing multiplier is within kPinned of ±1).
      if (found.located && signature(found.before->mu) == signature(a.mu) &&
          signature(found.after->mu) == signature(b.mu)) {
        step_found_.push_back({type, -1, found, a.p(), b.p()});
        return;
      }
      if (!found.located && !can_cut(s, depth)) {
        step_found_.push_back({type, -1, found, a.p(), b.p()});
        return;
      }
    }
    std::optional<Point> half;
    if (can_cut(s, depth)) half = point_between(a, b, s, period);
    if (!half) {
      note(fmt::format("between {} = {:.10g} and {:.10g} on branch {} the multipliers' signature "
                       "changes by more than one event that could not be told apart (the step "
                       "cannot be cut further); each kind of change located on the whole step",
                       options_.parameter.name(), a.p(), b.p(), branch));
      located_by_parity(a, b, s, period);
      return;
    }
    ++result_.step_cuts;
    const Vector to_b = b.u - half->u;
    explain_signature(a, *half, 0.5 * s, branch, period, depth + 1);
    explain_signature(*half, b, half->tangent.dot(to_b), branch, period, depth + 1);
  }

  // Whether an interval of arclength s at this depth of cutting may be cut again.
  bool can_cut(double s, int depth) const {
    return depth < kMaxCuts && std::abs(s) > 2 * std::min(min_step_, 1e-9 * (hi_ - lo_));
  }

  // The branch's point at half the arclength s from a toward b, corrected onto the branch along
  // a's tangent, with its multipliers, ∂F/∂p and tangent; empty where the corrector fails.
  std::optional<Point> point_between(Point& a, Point& b, double s, int period) {
    const Vector guess = 0.5 * (a.u + b.u);
    const Vector prediction = a.u + (0.5 * s) * a.tangent;
    Matrix monodromy;
    if (chord_) monodromy = 0.5 * (a.M + b.M);
    std::optional<Point> pt = correct_from(guess, prediction, a.tangent, a.b, period,
                                           chord_ ? &monodromy : nullptr,
                                           options_.max_corrections + 3, true, 0.0, &a);
    if (!pt) return std::nullopt;
    pt->b = parameter_derivative(pt->y(), pt->p(), period);
    pt->tangent = tangent_at(*pt, a.tangent, period);
    return pt;
  }

  // The old rule, where the step cannot be cut further: each kind whose count changes by an odd
  // number (folds, period doublings) or whose complex pairs outside change, located on the whole
  // step, with a note.
  void located_by_parity(Point& a, Point& b, double s, int period) {
    const Signature sa = signature(a.mu), sb = signature(b.mu);
    std::vector<BifurcationType> types;
    if ((sa.real_above_one - sb.real_above_one) % 2 != 0) types.push_back(BifurcationType::fold);
    if ((sa.real_below_minus_one - sb.real_below_minus_one) % 2 != 0) {
      types.push_back(BifurcationType::period_doubling);
    }
    if (((sa.complex_outside - sb.complex_outside) / 2) % 2 != 0) {
      types.push_back(BifurcationType::neimark_sacker);
    }
    for (const BifurcationType type : types) {
      step_found_.push_back({type, -1, locate(a, b, s, type, -1, period), a.p(), b.p()});
    }
  }

  // `variant` picks among the test functions of one kind: the first one whose signs differ at the
  // two ends of the bracket is used.
  static constexpr int kVariants = 2;
  double test_function(Point& pt, BifurcationType type, int which, int period, int variant) {
    if (variant == 1) {
      switch (type) {
        case BifurcationType::fold: return nearest_real(pt.mu, 1.0) - 1.0;
        case BifurcationType::period_doubling: return nearest_real(pt.mu, -1.0) + 1.0;
        case BifurcationType::neimark_sacker: {
          double product = 1.0;
          for (const auto& m : pt.mu.values) {
            if (!is_real(m) && m.imag() > 0) product *= std::norm(m) - 1.0;
          }
          return product;
        }
        case BifurcationType::grazing: break;
      }
    }
    switch (type) {
      // det(M − I) and det(M + I) = Π (μ_i ± 1): continuous, and of opposite signs on the two
      // sides of an odd number of real crossings of ±1 (which the detection saw), whichever
      // multiplier crosses, and however fast near a grazing.
      case BifurcationType::fold: return pt.mu.shifted_determinant(1.0);
      case BifurcationType::period_doubling: return pt.mu.shifted_determinant(-1.0);
      // The modulus of the complex pair nearest the circle, less 1 (the second variant: Π over
      // the complex pairs of (|μ|² − 1), which changes sign where one pair crosses). Both jump
      // where multipliers collide on the real axis; explain_signature checks the bracket a
      // location ends on and cuts the step where it landed on such a jump.
      case BifurcationType::neimark_sacker: return std::abs(nearest_complex_to_circle(pt.mu)) - 1.0;
      case BifurcationType::grazing: {
        const OrbitProfile& prof = profile_of(pt, period);
        return which % 2 == 0 ? prof.max_gap(which / 2) : prof.min_gap(which / 2);
      }
    }
    return std::numeric_limits<double>::quiet_NaN();
  }

  // A test function's zero between two points of the branch: the trial point nearest it, its
  // value, and the two points of the final bracket in the order of the arclength (the one toward
  // a first), each with its multipliers.
  struct Located {
    Point best;
    double test_value = 0.0;
    bool located = false;
    std::optional<Point> before, after;
  };

  // Locates the zero of the test function of `type` (`which`: the spring and extreme of a
  // grazing) between a and b, b at arclength h along a's tangent: the Illinois variant of regula
  // falsi on the arclength, every trial point corrected onto the branch.
  Located locate(Point& a, Point& b, double h, BifurcationType type, int which, int period) {
    int variant = 0;
    double fa = test_function(a, type, which, period, 0);
    double fb = test_function(b, type, which, period, 0);
    for (int v = 1; v < kVariants && !(std::isfinite(fa) && std::isfinite(fb) && fa * fb <= 0);
         ++v) {
      if (type == BifurcationType::grazing) break;
      variant = v;
      fa = test_function(a, type, which, period, v);
      fb = test_function(b, type, which, period, v);
    }
    const auto trial = [&](double s, const Point& end_a, double sa, const Point& end_b,
                           double sb) -> std::optional<std::pair<Point, double>> {
      // Predict by interpolating the bracket's ends, constrain to a's tangent at arclength s.
      const double w = (s - sa) / (sb - sa);
      const Vector guess = (1 - w) * end_a.u + w * end_b.u;
      const Vector prediction = a.u + s * a.tangent;
      // The chord corrector starts from the monodromy interpolated like the guess.
      Matrix monodromy;
      if (chord_) {
        const double along = std::clamp(s / h, 0.0, 1.0);
        monodromy = (1 - along) * a.M + along * b.M;
      }
      std::optional<Point> pt =
          correct_from(guess, prediction, a.tangent, a.b, period, chord_ ? &monodromy : nullptr,
                       options_.max_corrections + 3, type != BifurcationType::grazing,
                       kLocateResidual, &end_a);
      if (!pt) return std::nullopt;
      const double f = test_function(*pt, type, which, period, variant);
      return std::pair<Point, double>{std::move(*pt), f};
    };
    const auto small = [&](const Point& end_a, double sa, const Point& end_b, double sb) {
      return std::abs(end_b.p() - end_a.p()) <= options_.locate_tolerance &&
             std::abs(sb - sa) <= 1e-6 * std::abs(h);
    };
    ArclengthZero<Point> zero = zero_on_arclength(a, fa, b, fb, h, trial, small);
    Located out;
    out.best = std::move(zero.best);
    out.test_value = zero.value;
    out.located = zero.located;
    out.before = std::move(zero.before);
    out.after = std::move(zero.after);
    return out;
  }

  // Records a bifurcation located (or only detected) between the points at `from` and `to`.
  void record(BifurcationType type, int which, int branch, int period, const Located& found,
              double from, double to) {
    const Point& best = found.best;
    Bifurcation bif;
    bif.type = type;
    bif.branch = branch;
    bif.period = period;
    bif.parameter = best.p();
    bif.state = best.y();
    bif.test_value = found.test_value;
    if (type == BifurcationType::fold) bif.multiplier = nearest_real(best.mu, 1.0);
    if (type == BifurcationType::period_doubling) bif.multiplier = nearest_real(best.mu, -1.0);
    if (type == BifurcationType::neimark_sacker) bif.multiplier = nearest_complex_to_circle(best.mu);
    if (type == BifurcationType::grazing) {
      bif.spring = which / 2;
      bif.at_largest_gap = which % 2 == 0;
    }
    bif.located = found.located;
    // A switched branch that meets a bifurcation of its own again retraces its orbits, each now
    // started some periods later (a period-2k loop traversed as its two halves): stop it there.
    if (branch > 0) {
      for (const Bifurcation& other : result_.bifurcations) {
        if (other.branch == branch && other.type == type && other.spring == bif.spring &&
            std::abs(other.parameter - bif.parameter) <= 1e-6 * (hi_ - lo_)) {
          retracing_ = true;
          return;
        }
      }
    }
    if (!found.located) {
      note(fmt::format("{} near {} = {:.10g} on branch {}: detected, not located (bracket {:.10g} "
                       "to {:.10g})",
                       bifurcation_name(type), options_.parameter.name(), best.p(), branch, from,
                       to));
    }
    result_.bifurcations.push_back(bif);
    if (observer_ != nullptr) observer_->bifurcation(bif);
    if (type == BifurcationType::period_doubling && options_.switch_branches && found.located) {
      pending_.push_back({best, period, result_.bifurcations.size() - 1});
    }
  }

  // The corrector: F(y, p) = 0 with the constraint τ · (u − prediction) = 0 in u = (y, p), solved
  // from `guess` on the core (correct_on_curve). `b` is ∂F/∂p near the prediction (kept fixed: a
  // chord in that column). Empty when it does not converge or the motion blows up.
  //
  // Newton forms the monodromy at every iterate. The Newton-chord corrector (the default above
  // 20 state components) keeps the monodromy `monodromy` of a point nearby (the point predicted
  // from, or between the two ends of a bifurcation's bracket the monodromy interpolated like the
  // guess) while the residual falls at least fourfold a step. Forming the monodromy integrates
  // the map with all its tangent columns, many times the cost of one integration, so a corrector
  // forms it about once, at the orbit it converges to, where its multipliers are wanted. The orbit
  // found is the one Newton finds, to the same tolerance: only the path to it differs.
  // `corrections` bounds the monodromies formed before convergence. Without `multipliers` (a
  // grazing's trial points, whose test function is the orbit's profile) the chord corrector
  // leaves the orbit's monodromy and multipliers out. A `polish` below the shooting tolerance (a
  // bifurcation's trial points) closes the orbit further (CorrectorSettings::polish).
  //
  // Matrix-free (beyond the dense limit) the corrector is correct_matrix_free, Newton-Krylov with
  // `2 * corrections` steps at most, and the multipliers come from Davidson or Arnoldi
  // (leading_multipliers.hpp) warm-started from the point `near`'s (its Ritz vectors' real Schur
  // vectors).
  std::optional<Point> correct_from(const Vector& guess, const Vector& prediction,
                                    const Vector& tau, const Vector& b, int period,
                                    const Matrix* monodromy, int corrections,
                                    bool multipliers = true, double polish = 0.0,
                                    const Point* near = nullptr) {
    if (matrix_free_) {
      return correct_matrix_free(guess, prediction, tau, b, period, 2 * corrections, multipliers,
                                 polish, near);
    }
    OrbitEquations equations(*this, period, b);
    Matrix start;
    if (chord_ && monodromy != nullptr) start = orbit_jacobian(*monodromy, b);
    CorrectorSettings settings;
    settings.chord = chord_;
    settings.corrections = corrections;
    settings.tolerance = options_.shooting.tolerance;
    settings.polish = polish;
    settings.jacobian_at_solution = multipliers;
    std::optional<CorrectedPoint> c =
        correct_on_curve(equations, guess, prediction, tau, start.size() > 0 ? &start : nullptr,
                         settings, &result_.chord_stalls);
    if (!c) return std::nullopt;
    Point pt;
    pt.u = std::move(c->u);
    pt.residual = c->residual;
    pt.iterations = c->iterations;
    pt.formed = c->formed;
    if (c->jacobian.size() > 0) {
      pt.M = equations.monodromy();
      pt.mu = floquet_multipliers(pt.M);
    }
    return pt;
  }

  void switch_branch(Pending& pd) {
    const int period = 2 * pd.period;
    const Index N = pd.at.n();
    // The eigenvector of the multiplier nearest −1 (matrix-free: its Ritz vector).
    Vector v;
    if (matrix_free_) {
      Index k = 0;
      const auto& values = pd.at.mu.values;
      for (Index i = 1; i < static_cast<Index>(values.size()); ++i) {
        if (std::abs(values[i] + 1.0) < std::abs(values[k] + 1.0)) k = i;
      }
      if (pd.at.ritz.cols() <= k) {
        note(fmt::format("branch switching at the period doubling at {} = {:.10g}: no eigenvector "
                         "of its multiplier -1",
                         options_.parameter.name(), pd.at.p()));
        return;
      }
      const Eigen::VectorXcd w = pd.at.ritz.col(k);
      v = w.real().norm() >= w.imag().norm() ? Vector(w.real()) : Vector(w.imag());
    } else {
      Eigen::EigenSolver<Matrix> eig(pd.at.M);
      Index k = 0;
      for (Index i = 1; i < eig.eigenvalues().size(); ++i) {
        if (std::abs(eig.eigenvalues()(i) + 1.0) < std::abs(eig.eigenvalues()(k) + 1.0)) k = i;
      }
      v = eig.eigenvectors().col(k).real();
    }
    v /= v.norm();
    Vector tau0 = Vector::Zero(N + 1);
    tau0.head(N) = v;
    const double scale = std::max(1.0, pd.at.y().norm());
    const Vector b0 = parameter_derivative(pd.at.y(), pd.at.p(), period);
    for (double eps : {1e-3, 1e-2, 3e-2, 1e-4}) {
      Vector prediction = pd.at.u;
      prediction.head(N) += eps * scale * v;
      // No monodromy to start from: the period-2k one at the period doubling, M², makes the
      // bordered matrix singular there (M² − I has v in its kernel, and ∂F/∂p lies in its range:
      // a pitchfork of the period-2k map), so the first is formed at y* + ε v.
      std::optional<Point> pt = correct_from(prediction, prediction, tau0, b0, period, nullptr,
                                             options_.max_corrections + 3, true, 0.0, &pd.at);
      if (!pt) continue;
      // A genuine period-2k orbit: not a fixed point of the period-k map.
      Vector Fk;
      try {
        Fk = residual(pt->y(), pt->p(), pd.period, nullptr);
      } catch (const Error&) {
        continue;
      }
      if (Fk.lpNorm<Eigen::Infinity>() <=
          1e3 * options_.shooting.tolerance * std::max(1.0, pt->y().lpNorm<Eigen::Infinity>())) {
        continue;
      }
      pt->b = parameter_derivative(pt->y(), pt->p(), period);
      pt->tangent = tangent_at(*pt, tau0, period);
      ++branches_;
      result_.bifurcations[pd.bifurcation].to_branch = branches_;
      follow(std::move(*pt), branches_, period, pd.period, pd.bifurcation);
      return;
    }
    // Second way: Newton at a fixed parameter a little to either side of the period doubling,
    // from y* ± ε v (the doubled orbit's size grows like the square root of the distance).
    const double range = hi_ - lo_;
    ShootingOptions shooting = options_.shooting;
    shooting.period = period;
    shooting.solver = matrix_free_ ? ShootingSolver::krylov : ShootingSolver::dense;
    shooting.multipliers = !matrix_free_;
    for (double delta : {1e-4 * range, 1e-3 * range, 1e-2 * range}) {
      for (double side : {1.0, -1.0}) {
        const double p = pd.at.p() + side * delta;
        std::string why;
        if (p < lo_ || p > hi_ || !model_.accepts(options_.parameter, p, &why)) continue;
        for (double eps : {1.0, 3.0, 10.0, 30.0}) {
          const Vector guess = pd.at.y() + eps * std::sqrt(delta) * scale * v;
          Point pt;
          try {
            const PeriodicOrbit orbit = find_periodic_orbit(map_at(p), guess, shooting);
            pt.u.resize(N + 1);
            pt.u << orbit.state, p;
            pt.M = orbit.monodromy;
            pt.mu = orbit.multipliers;
            pt.residual = orbit.residual;
            pt.iterations = orbit.iterations;
            result_.krylov_products += orbit.krylov_products;
            const Vector Fk = residual(orbit.state, p, pd.period, nullptr);
            if (Fk.lpNorm<Eigen::Infinity>() <=
                1e3 * options_.shooting.tolerance *
                    std::max(1.0, orbit.state.lpNorm<Eigen::Infinity>())) {
              continue;  // the period-k orbit again
            }
          } catch (const Error&) {
            continue;
          }
          if (matrix_free_) leading_multipliers(pt, period, &pd.at.ritz);
          pt.b = parameter_derivative(pt.y(), pt.p(), period);
          const Vector away = pt.u - pd.at.u;
          pt.tangent = tangent_at(pt, away / away.norm(), period);
          ++branches_;
          result_.bifurcations[pd.bifurcation].to_branch = branches_;
          follow(std::move(pt), branches_, period, pd.period, pd.bifurcation);
          return;
        }
      }
    }
    note(fmt::format("branch switching at the period doubling at {} = {:.10g}: no period-{} orbit "
                     "found next to it",
                     options_.parameter.name(), pd.at.p(), period));
  }

  const analysis::PointModel& model_;
  bool chord_ = true;  // the corrector: chord steps, or Newton
  bool matrix_free_ = false;  // beyond the dense limit: Newton-Krylov and Arnoldi
  std::optional<detail::OpenStructurePreconditioner> open_;  // matrix-free: GMRES's preconditioner
  // Matrix-free: GMRES's recycled subspace (gmres.hpp), kept across a solve's restarts and
  // dropped at each new bordered system.
  detail::RecycledSubspace recycled_;
  const ContinuationOptions& options_;
  ContinuationObserver* observer_;
  ContinuationResult& result_;
  std::map<double, StroboscopicMap> maps_;
  std::deque<Pending> pending_;
  int branches_ = 0;
  bool retracing_ = false;
  // The bifurcations found in the step being explained, before they are recorded in their order
  // along the branch.
  struct Found {
    BifurcationType type;
    int which;  // grazing: spring * 2 + (0: largest gap, 1: smallest)
    Located where;
    double from, to;  // the parameter at the ends of the interval it was found in
  };
  std::vector<Found> step_found_;
  double branch_start_ = 0.0;  // parameter of the first point of the branch being followed
  double initial_step_ = 0, min_step_ = 0, max_step_ = 0, lo_ = 0, hi_ = 0;
};

}  // namespace

ContinuationResult continue_periodic_orbit(const analysis::PointModel& model, const Vector& guess,
                                           const ContinuationOptions& options,
                                           ContinuationObserver* observer) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (!model.has(options.parameter, &why)) throw InputError(why);
  if (!model.accepts(options.parameter, options.start, &why)) throw InputError(why);
  ContinuationResult result;
  Continuer continuer(model, options, observer, result);
  continuer.run(guess);
  return result;
}

}  // namespace pwl::orbits
