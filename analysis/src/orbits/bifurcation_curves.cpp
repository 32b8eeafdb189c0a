#include "pwl/orbits/bifurcation_curves.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "curve_systems.hpp"
#include "matrix_free_grazing.hpp"
#include "matrix_free_bordered.hpp"
#include "pwl/errors.hpp"

namespace pwl::orbits {

std::string curve_type_name(CurveType type) {
  switch (type) {
    case CurveType::fold: return "fold";
    case CurveType::period_doubling: return "period-doubling";
    case CurveType::neimark_sacker: return "neimark-sacker";
    case CurveType::grazing: return "grazing";
  }
  return "?";
}

CurveType parse_curve_type(const std::string& name) {
  for (CurveType t : {CurveType::fold, CurveType::period_doubling, CurveType::neimark_sacker,
                      CurveType::grazing}) {
    if (curve_type_name(t) == name) return t;
  }
  throw InputError(fmt::format("curve type \"{}\" is not known; use fold, period-doubling, "
                               "neimark-sacker or grazing",
                               name));
}

CurveType curve_type_of(BifurcationType type) {
  switch (type) {
    case BifurcationType::fold: return CurveType::fold;
    case BifurcationType::period_doubling: return CurveType::period_doubling;
    case BifurcationType::neimark_sacker: return CurveType::neimark_sacker;
    case BifurcationType::grazing: return CurveType::grazing;
  }
  return CurveType::fold;
}

bool CurvesOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (first == second) {
    *why = fmt::format("the second parameter {} is the first: give another", second.name());
    return false;
  }
  for (const auto& [name, a, b] : {std::tuple{"P range", p_from, p_to},
                                   std::tuple{"Q range", q_from, q_to}}) {
    if (!std::isfinite(a) || !std::isfinite(b) || a == b) {
      *why = fmt::format("{} {}:{} must be two different finite values", name, a, b);
      return false;
    }
  }
  if (!walk_settings_valid(initial_step, min_step, max_step, max_points, max_corrections,
                           locate_tolerance, why)) {
    return false;
  }
  if (types.empty()) {
    *why = "no curve type to follow";
    return false;
  }
  if (profile_samples < 8) {
    *why = fmt::format("profile samples = {} must be >= 8", profile_samples);
    return false;
  }
  return shooting.is_valid(why);
}

namespace {

using curves_detail::CurveSystem;
using curves_detail::GrazingSystem;
using curves_detail::NeimarkSackerSystem;
using curves_detail::MatrixFreeCurve;
using curves_detail::MatrixFreeGrazing;
using curves_detail::MatrixFreeBordered;
using curves_detail::PlaneMaps;
using curves_detail::SingularSystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Corrector::automatic takes the chord corrector above this many state components (as the
// one-parameter continuation does).
constexpr Index kChordAbove = 20;
// A codimension-two point's trial points are closed to this residual where the corrector gets
// there (continuation.cpp, kLocateResidual, says why).
constexpr double kLocateResidual = 1e-12;
// Relative steps of the differences of the map that give the normal-form coefficients: a second
// difference (B) and a third (C), each balancing truncation against rounding.
constexpr double kSecondDifference = 1e-4;
constexpr double kThirdDifference = 1e-3;
// A curve that advances this many steps in a row at its smallest steps ends there
// (StepControl::stall_steps): it meets a point where it is not smooth, usually a grazing.
constexpr int kStallSteps = 20;

// A point of a curve: the unknowns, and what was computed there.
struct CurvePt : CurvePoint {
  Matrix jacobian;  // ∂G/∂u (the chord corrector's start, the tangent)
  Matrix M;         // monodromy (dense only)
  FloquetMultipliers mu;
  Eigen::MatrixXcd ritz;  // matrix-free: the Ritz vectors of mu (the next point's warm start)
  std::optional<OrbitProfile> profile;
  std::vector<double> tests;  // the curve's codimension-two test functions (NaN: not computed)
};

// Re Π (μ_i − target) over every multiplier but the one nearest `target` (dense curves: all of
// them): zero where a second multiplier reaches target.
double second_product(const FloquetMultipliers& mu, double target) {
  std::size_t nearest = mu.values.size();
  for (std::size_t i = 0; i < mu.values.size(); ++i) {
    if (nearest == mu.values.size() ||
        std::abs(mu.values[i] - target) < std::abs(mu.values[nearest] - target)) {
      nearest = i;
    }
  }
  std::complex<double> product = 1.0;
  for (std::size_t i = 0; i < mu.values.size(); ++i) {
    if (i != nearest) product *= mu.values[i] - target;
  }
  return product.real();
}

bool is_complex(const std::complex<double>& m) {
  return std::abs(m.imag()) > 1e-9 * std::max(1.0, std::abs(m));
}

// |μ| − 1 of the complex pair nearest the unit circle (NaN without one): zero where a pair
// crosses it, and continuous while that pair stays complex and nearest.
double nearest_pair_distance(const FloquetMultipliers& mu) {
  double best = kNaN;
  for (const auto& m : mu.values) {
    if (!is_complex(m)) continue;
    const double d = std::abs(m) - 1.0;
    if (std::isnan(best) || std::abs(d) < std::abs(best)) best = d;
  }
  return best;
}

// Complex multipliers outside the unit circle.
int complex_outside(const FloquetMultipliers& mu) {
  int count = 0;
  for (const auto& m : mu.values) count += is_complex(m) && std::abs(m) > 1;
  return count;
}

// One codimension-two test of a curve.
struct Test {
  enum class Kind {
    det_minus,       // det(I − M), over the leading multipliers where matrix-free
    det_plus,        // det(I + M), likewise
    second_plus,     // Re Π(μ − 1) without the multiplier nearest +1
    second_minus,    // Re Π(μ + 1) without the multiplier nearest −1
    kappa,           // κ − value
    complex_pairs,   // |μ| − 1 of the complex pair nearest the circle, where their count changes
    gap,             // an extreme of a gap function
    cusp,            // the fold's normal-form coefficient a
    generalised_pd,  // the period doubling's normal-form coefficient c
  };
  Kind kind;
  std::string type;  // the codimension-two point it finds
  double value = 0.0;       // kappa: the resonance's κ
  int spring = -1;          // gap: the spring and its extreme
  bool at_largest = true;
};

// Whether curves of n state components form the monodromy: the solver dense, or automatic within
// the dense limit; krylov, or automatic beyond the limit, are matrix-free.
bool dense_allowed(const ShootingOptions& s, Index n) {
  if (s.solver == ShootingSolver::dense) return true;
  if (s.solver == ShootingSolver::krylov) return false;
  return n <= s.dense_state_limit;
}

std::string gap_detail(int spring, bool at_largest) {
  return fmt::format("spring {} ({} gap)", spring + 1, at_largest ? "largest" : "smallest");
}

class CurvesRunner {
 public:
  CurvesRunner(const analysis::PointModel& model, const CurvesOptions& options,
               CurvesObserver* observer, CurvesResult& result)
      : model_(model),
        options_(options),
        observer_(observer),
        result_(result),
        maps_(model, options, result),
        p_scale_(std::abs(options.p_to - options.p_from)),
        q_scale_(std::abs(options.q_to - options.q_from)) {
    p_lo_ = std::min(options.p_from, options.p_to);
    p_hi_ = std::max(options.p_from, options.p_to);
    q_lo_ = std::min(options.q_from, options.q_to);
    q_hi_ = std::max(options.q_from, options.q_to);
    q0_ = model.value(options.second);
    steps_.initial = options.initial_step > 0 ? options.initial_step : 0.01;
    steps_.min = options.min_step > 0 ? options.min_step : 1e-7;
    steps_.max = options.max_step > 0 ? options.max_step : 0.04;
    steps_.stall_steps = kStallSteps;
    springs_ = static_cast<int>(
        model.with(options.second, q0_).point_case().structure.spring_count());
  }

  void run(const std::vector<Bifurcation>& starts) {
    for (std::size_t i = 0; i < starts.size(); ++i) {
      const Bifurcation& b = starts[i];
      const CurveType type = curve_type_of(b.type);
      if (std::find(options_.types.begin(), options_.types.end(), type) == options_.types.end()) {
        continue;
      }
      if (!b.located) {
        note(fmt::format("{} near {} = {:.10g}: only detected on its branch, no curve followed",
                         bifurcation_name(b.type), options_.first.name(), b.parameter));
        continue;
      }
      follow(b);
    }
  }

 private:
  // The curve of one bifurcation, in both directions from it (unless an earlier curve passed
  // through it: the same curve).
  void follow(const Bifurcation& b) {
    for (const Crossing& c : crossings_) {
      if (c.type == curve_type_of(b.type) && c.period == b.period &&
          (c.type != CurveType::grazing ||
           (c.spring == b.spring && c.at_largest == b.at_largest_gap)) &&
          std::abs(c.p - b.parameter) <= 1e-7 * p_scale_) {
        note(fmt::format("the {} at {} = {:.10g} lies on curve {}, followed already", 
                         bifurcation_name(b.type), options_.first.name(), b.parameter, c.curve));
        return;
      }
    }
    const int id = static_cast<int>(result_.curves.size());
    CurveSummary summary;
    summary.curve = id;
    summary.type = curve_type_of(b.type);
    summary.period = b.period;
    summary.spring = b.spring;
    summary.at_largest_gap = b.at_largest_gap;
    const Index n = b.state.size();
    chord_ = options_.corrector == Corrector::chord ||
             (options_.corrector == Corrector::automatic && n > kChordAbove);
    std::unique_ptr<CurveSystem> system;
    std::optional<double> aux;
    try {
      system = make_system(b, aux);
    } catch (const Error& e) {
      note(fmt::format("curve {} ({} at {} = {:.10g}): cannot start: {}", id,
                       curve_type_name(summary.type), options_.first.name(), b.parameter,
                       e.what()));
      return;
    }
    if (!system) {
      note(fmt::format("curve {} ({} at {} = {:.10g}): cannot start: no multiplier on the unit "
                       "circle there",
                       id, curve_type_name(summary.type), options_.first.name(), b.parameter));
      return;
    }
    system_ = system.get();
    free_ = dynamic_cast<MatrixFreeCurve*>(system_);
    warm_.resize(0, 0);
    type_ = summary.type;
    curve_ = id;
    spring_ = b.spring;
    at_largest_ = b.at_largest_gap;
    tests_ = tests_of(type_);
    if (free_ != nullptr && options_.codim2 &&
        (type_ == CurveType::fold || type_ == CurveType::period_doubling)) {
      note(fmt::format("curve {}: matrix-free, no {} point is looked for (its normal-form "
                       "coefficient needs the left null vector, products with the transposed "
                       "monodromy)",
                       id, type_ == CurveType::fold ? "cusp" : "generalised period-doubling"));
    }
    unreliable_noted_ = false;
    untrusted_noted_ = false;
    // The first point: the curve's equations with q held at the branch's value.
    const Vector guess = system->unknowns(b.state, b.parameter, q0_, aux);
    Vector hold = Vector::Zero(guess.size());
    hold(n + 1) = 1.0;
    std::optional<CurvePt> first = corrected(guess, guess, hold, nullptr, options_.max_corrections + 3, 0.0);
    if (first) {
      system_->refresh();
      first = corrected(first->u, first->u, hold, nullptr, options_.max_corrections + 3, 0.0);
    }
    if (!first) {
      note(fmt::format("curve {} ({} at {} = {:.10g}): its defining system has no solution "
                       "there",
                       id, curve_type_name(summary.type), options_.first.name(), b.parameter));
      return;
    }
    system_->refresh();
    first->tangent = tangent_at(*first, hold);
    if (!first->tangent.allFinite()) {
      Vector along_p = Vector::Zero(guess.size());
      along_p(n) = 1.0;
      first->tangent = tangent_at(*first, along_p);
    }
    warm_ = first->ritz;
    summary.start_p = system_->p(first->u);
    summary.start_q = system_->q(first->u);
    emit(*first);
    int points = 1;
    bool closed = false;
    for (int direction = 0; direction < 2 && !closed; ++direction) {
      CurvePt start = *first;
      warm_ = first->ritz;  // each direction's Arnoldi warm-started from the curve's first point
      if (direction == 1) {
        start.tangent = -first->tangent;
        emit(*first);  // each direction's rows start at the curve's first point
      }
      Walk walk(*this, *first);
      CurvePt last;
      // Matrix-free, the step follows the predictor's error (StepControl's rule for the chord
      // corrector): inexact Newton's iterations, whose forcing tightens as the residual falls,
      // say as little about the step as the chord's.
      StepControl steps = steps_;
      steps.chord = free_ != nullptr;
      const WalkEnd end = walk.walk(std::move(start), steps, options_.max_points, &last);
      points += end.points - 1;
      std::string why;
      switch (end.kind) {
        case WalkEnd::Kind::max_points: why = "largest number of points reached"; break;
        case WalkEnd::Kind::min_step:
          why = stuck(last, "the step fell below its minimum");
          break;
        case WalkEnd::Kind::stalled:
          why = stuck(last, fmt::format("{} steps in a row at the smallest steps", kStallSteps));
          break;
        case WalkEnd::Kind::turns_back:
          why = stuck(last, "it turns back on itself even at the smallest step");
          break;
        case WalkEnd::Kind::problem: why = end.why; break;
      }
      closed = walk.closed();
      summary.ends[direction] = why;
      note(fmt::format("curve {} ({}{}, period {}), {}: {} after {} points", id,
                       curve_type_name(summary.type),
                       summary.spring >= 0 ? ", " + gap_detail(summary.spring, summary.at_largest_gap) : "",
                       summary.period, direction == 0 ? "forward" : "backward", why,
                       end.points));
    }
    if (closed) summary.ends[1] = "closed on itself";
    summary.points = points;
    result_.curves.push_back(summary);
  }

  // Why a curve cannot go on from its last point: `what`, and where, and the spring whose gap
  // extreme is nearest zero there when one is near (the curve meets a grazing, where the map is
  // not smooth).
  std::string stuck(CurvePt& last, const std::string& what) {
    std::string text = fmt::format("cannot go on at {} = {:.10g}, {} = {:.10g} ({})",
                                   options_.first.name(), system_->p(last.u),
                                   options_.second.name(), system_->q(last.u), what);
    try {
      const OrbitProfile& profile = profile_of(last);
      int nearest = -1;
      bool largest = true;
      double smallest = std::numeric_limits<double>::infinity();
      const double scale = std::max(1e-300, profile.amplitude.maxCoeff());
      for (Index j = 0; j < profile.max_gap.size(); ++j) {
        for (const bool at_max : {true, false}) {
          if (type_ == CurveType::grazing && j == spring_ && at_max == at_largest_) continue;
          const double g = std::abs(at_max ? profile.max_gap(j) : profile.min_gap(j));
          if (g < smallest) {
            smallest = g, nearest = static_cast<int>(j), largest = at_max;
          }
        }
      }
      if (nearest >= 0 && smallest <= 1e-4 * scale) {
        text += fmt::format(": there {}'s extreme is {:.1e} from zero, a grazing where the map "
                            "is not smooth",
                            gap_detail(nearest, largest), smallest);
      }
    } catch (const Error&) {
    }
    return text;
  }

  // The defining system of the curve through the bifurcation b, and its auxiliary unknown.
  std::unique_ptr<CurveSystem> make_system(const Bifurcation& b, std::optional<double>& aux) {
    const Index n = b.state.size();
    const int k = b.period;
    if (b.type == BifurcationType::grazing) {
      if (matrix_free(n)) {
        return std::make_unique<MatrixFreeGrazing>(maps_, k, n, p_scale_, q_scale_, b.spring,
                                                   b.at_largest_gap, b.parameter, q0_);
      }
      return std::make_unique<GrazingSystem>(maps_, k, n, p_scale_, q_scale_, b.spring,
                                             b.at_largest_gap);
    }
    if (matrix_free(n)) {
      // The borders: the Ritz vector of the multiplier nearest σ (its phase turned so that its
      // largest entry is real), or the real and imaginary parts of the pair's; none where Arnoldi
      // finds no such multiplier within kOnCircle of the unit circle (the branch located the
      // bifurcation to 1e-8 in its parameter).
      std::complex<double> target = b.type == BifurcationType::fold ? 1.0 : -1.0;
      if (b.type == BifurcationType::neimark_sacker) {
        target = b.multiplier.imag() < 0 ? std::conj(b.multiplier) : b.multiplier;
      }
      Eigen::MatrixXcd ritz;
      curves_detail::CurvePreconditioner open(maps_, k, b.parameter, q0_, 1.0);
      const FloquetMultipliers mu = curves_detail::leading_multipliers(
          maps_, b.state, b.parameter, q0_, k, open.at(b.parameter, q0_), nullptr, &ritz,
          MatrixFreeBordered::kOnCircle);
      Index best = -1;
      for (Index i = 0; i < static_cast<Index>(mu.values.size()); ++i) {
        if (best < 0 || std::abs(mu.values[i] - target) < std::abs(mu.values[best] - target)) {
          best = i;
        }
      }
      if (best < 0 || ritz.cols() <= best ||
          std::abs(std::abs(mu.values[best]) - 1.0) > MatrixFreeBordered::kOnCircle ||
          std::abs(mu.values[best] - target) > 0.1) {
        return nullptr;
      }
      const std::complex<double> found = mu.values[best];
      const Eigen::VectorXcd z = ritz.col(best);
      Matrix right;
      if (b.type == BifurcationType::neimark_sacker) {
        if (std::abs(found.imag()) < 1e-9) return nullptr;
        right.resize(n, 2);
        right << z.real(), z.imag();
        aux = found.real() / std::abs(found);
      } else {
        Index largest = 0;
        z.cwiseAbs().maxCoeff(&largest);
        right = (z * (std::abs(z(largest)) / z(largest))).real();
      }
      return std::make_unique<MatrixFreeBordered>(maps_, k, n, p_scale_, q_scale_,
                                                  curve_type_of(b.type), right, b.parameter, q0_);
    }
    Matrix M = Matrix::Identity(n, n);
    maps_.advance(b.state, b.parameter, q0_, k, &M);
    const Eigen::EigenSolver<Matrix> right(M), left(M.transpose());
    const auto nearest = [](const Eigen::EigenSolver<Matrix>& e, std::complex<double> target) {
      Index best = 0;
      for (Index i = 1; i < e.eigenvalues().size(); ++i) {
        if (std::abs(e.eigenvalues()(i) - target) < std::abs(e.eigenvalues()(best) - target)) {
          best = i;
        }
      }
      return best;
    };
    if (b.type == BifurcationType::fold || b.type == BifurcationType::period_doubling) {
      const double sigma = b.type == BifurcationType::fold ? 1.0 : -1.0;
      const Vector w = right.eigenvectors().col(nearest(right, sigma)).real();
      const Vector v = left.eigenvectors().col(nearest(left, sigma)).real();
      return std::make_unique<SingularSystem>(maps_, k, n, p_scale_, q_scale_, sigma, w, v);
    }
    // Neimark–Sacker: the pair on the unit circle, κ = Re μ.
    std::complex<double> mu = b.multiplier;
    if (mu.imag() < 0) mu = std::conj(mu);
    const Index i = nearest(right, mu);
    const Index j = nearest(left, mu);
    const std::complex<double> found = right.eigenvalues()(i);
    if (std::abs(found.imag()) < 1e-9) return nullptr;
    Matrix W(n, 2), V(n, 2);
    W << right.eigenvectors().col(i).real(), right.eigenvectors().col(i).imag();
    V << left.eigenvectors().col(j).real(), left.eigenvectors().col(j).imag();
    aux = found.real() / std::abs(found);
    return std::make_unique<NeimarkSackerSystem>(maps_, k, n, p_scale_, q_scale_, W, V);
  }

  // The curve's codimension-two tests (bifurcation_curves.hpp lists them). Matrix-free, not the
  // cusp's or the generalised period doubling's coefficient: they need the left null vector.
  std::vector<Test> tests_of(CurveType type) const {
    using K = Test::Kind;
    std::vector<Test> tests;
    if (!options_.codim2) return tests;
    std::string grazing_name;
    switch (type) {
      case CurveType::fold:
        tests.push_back({K::det_plus, "fold-flip"});
        tests.push_back({K::second_plus, "resonance-1:1"});
        if (free_ == nullptr) tests.push_back({K::cusp, "cusp"});
        grazing_name = "fold-grazing";
        break;
      case CurveType::period_doubling:
        tests.push_back({K::det_minus, "fold-flip"});
        tests.push_back({K::second_minus, "resonance-1:2"});
        if (free_ == nullptr) {
          tests.push_back({K::generalised_pd, "generalised-period-doubling"});
        }
        grazing_name = "period-doubling-grazing";
        break;
      case CurveType::neimark_sacker:
        tests.push_back({K::kappa, "resonance-1:1", 1.0});
        tests.push_back({K::kappa, "resonance-1:2", -1.0});
        tests.push_back({K::kappa, "resonance-1:3", -0.5});
        tests.push_back({K::kappa, "resonance-1:4", 0.0});
        tests.push_back({K::det_minus, "fold-neimark-sacker"});
        tests.push_back({K::det_plus, "period-doubling-neimark-sacker"});
        grazing_name = "neimark-sacker-grazing";
        break;
      case CurveType::grazing:
        tests.push_back({K::det_minus, "fold-grazing"});
        tests.push_back({K::det_plus, "period-doubling-grazing"});
        tests.push_back({K::complex_pairs, "neimark-sacker-grazing"});
        grazing_name = "double-grazing";
        break;
    }
    for (int j = 0; j < springs_; ++j) {
      for (const bool largest : {true, false}) {
        if (type == CurveType::grazing && j == spring_ && largest == at_largest_) continue;
        Test t{K::gap, grazing_name};
        t.spring = j;
        t.at_largest = largest;
        tests.push_back(t);
      }
    }
    return tests;
  }

  // The orbit's profile at a point (kept).
  const OrbitProfile& profile_of(CurvePt& pt) {
    if (!pt.profile) {
      pt.profile = maps_.profile(pt.u.head(system_->state_size()), system_->p(pt.u),
                                 system_->q(pt.u), system_->period());
    }
    return *pt.profile;
  }

  // Whether a curve of n state components is followed matrix-free: where the solver is krylov, or
  // automatic beyond the dense limit.
  bool matrix_free(Index n) const { return !dense_allowed(options_.shooting, n); }

  // The unit tangent at a corrected point, oriented like `previous`.
  Vector tangent_at(const CurvePt& pt, const Vector& previous) {
    if (free_ != nullptr) return free_->tangent(pt.u, previous);
    return curve_tangent(pt.jacobian, previous);
  }

  // The curve's point corrected from `guess` with τ · (u − prediction) = 0, completed with its
  // multipliers and its tests. Matrix-free: by Newton–Krylov (twice as many steps as the dense
  // corrector forms Jacobians, as the one-parameter continuation allows), and the leading
  // multipliers by Davidson or Arnoldi (leading_multipliers.hpp) warm-started from the last
  // accepted point's.
  std::optional<CurvePt> corrected(const Vector& guess, const Vector& prediction,
                                   const Vector& tau, const Matrix* start, int corrections,
                                   double polish) {
    if (free_ != nullptr) {
      std::optional<MatrixFreeCurve::Corrected> c =
          free_->correct(guess, prediction, tau, 2 * corrections, polish);
      if (!c) return std::nullopt;
      CurvePt pt;
      pt.u = std::move(c->u);
      pt.residual = c->residual;
      pt.iterations = c->iterations;
      pt.mu = free_->multipliers(pt.u, warm_.size() > 0 ? &warm_ : nullptr, &pt.ritz);
      if (pt.mu.method == FloquetMultipliers::Method::davidson) ++result_.davidson_points;
      if (pt.mu.method == FloquetMultipliers::Method::arnoldi) ++result_.arnoldi_points;
      if (!pt.mu.converged) {
        ++result_.unconverged_multipliers;
      } else if (!pt.mu.band_covered) {
        ++result_.uncovered_bands;
      }
      pt.tests = evaluate_tests(pt);
      return pt;
    }
    std::optional<CorrectedPoint> c = correct_on_curve(
        *system_, guess, prediction, tau, start, corrector_settings(corrections, polish, true));
    if (!c) return std::nullopt;
    CurvePt pt;
    pt.u = std::move(c->u);
    pt.jacobian = std::move(c->jacobian);
    pt.residual = c->residual;
    pt.iterations = c->iterations;
    pt.M = system_->monodromy();
    pt.mu = floquet_multipliers(pt.M);
    pt.tests = evaluate_tests(pt);
    return pt;
  }

  std::vector<double> evaluate_tests(CurvePt& pt) {
    std::vector<double> values;
    values.reserve(tests_.size());
    // Matrix-free: the multipliers' tests rest on Arnoldi having converged and reported every
    // multiplier outside the circle; where it did not, they are not evaluated (as the branch does
    // not claim a stability change there), and the curve says so once.
    const bool trusted = pt.mu.converged && pt.mu.band_covered;
    if (!trusted && !untrusted_noted_) {
      note(fmt::format("curve {}: at {} = {:.10g}, {} = {:.10g} Arnoldi {}: no fold-, flip- or "
                       "Neimark-Sacker-grazing point is looked for where that holds",
                       curve_, options_.first.name(), system_->p(pt.u), options_.second.name(),
                       system_->q(pt.u),
                       pt.mu.converged ? "did not reach below the band of multipliers it must cover"
                                       : "stopped short of its tolerance"));
      untrusted_noted_ = true;
    }
    for (const Test& t : tests_) {
      using K = Test::Kind;
      double v = kNaN;
      const bool multipliers = t.kind != K::kappa && t.kind != K::gap && t.kind != K::cusp &&
                               t.kind != K::generalised_pd;
      if (multipliers && !trusted) {
        values.push_back(v);
        continue;
      }
      switch (t.kind) {
        case K::det_minus: v = pt.mu.shifted_determinant(1.0); break;
        case K::det_plus: v = pt.mu.shifted_determinant(-1.0); break;
        case K::second_plus: v = second_product(pt.mu, 1.0); break;
        case K::second_minus: v = second_product(pt.mu, -1.0); break;
        case K::kappa: v = pt.u(pt.u.size() - 1) - t.value; break;
        case K::complex_pairs: v = nearest_pair_distance(pt.mu); break;
        case K::gap: {
          const OrbitProfile& prof = profile_of(pt);
          v = t.at_largest ? prof.max_gap(t.spring) : prof.min_gap(t.spring);
          break;
        }
        case K::cusp: v = normal_form(pt, false); break;
        case K::generalised_pd: v = normal_form(pt, true); break;
      }
      values.push_back(v);
    }
    return values;
  }

  // The fold's a = ½⟨p, B(q, q)⟩ or the period doubling's c = (1/6)⟨p, C(q, q, q)⟩ +
  // ½⟨p, B(q, (I − A)⁻¹ B(q, q))⟩ at the point, from central differences of the map along q; NaN
  // where a gap extreme changes sign within the differences' reach (the map is not smooth there).
  double normal_form(CurvePt& pt, bool third) {
    auto* singular = dynamic_cast<SingularSystem*>(system_);
    if (singular == nullptr) return kNaN;
    const Index n = system_->state_size();
    const Vector y = pt.u.head(n);
    const double p = system_->p(pt.u), q = system_->q(pt.u);
    const int k = system_->period();
    const Vector qv = singular->right();
    const Vector pv = singular->left();
    const double h = (third ? kThirdDifference : kSecondDifference) *
                     std::max(1.0, y.lpNorm<Eigen::Infinity>());
    try {
      // The map's contact structure must not change within the reach of the differences.
      const OrbitProfile& here = profile_of(pt);
      const double reach = third ? 2 * h : h;
      for (const double sign : {1.0, -1.0}) {
        const OrbitProfile there = maps_.profile(y + sign * reach * qv, p, q, k);
        for (Index j = 0; j < here.max_gap.size(); ++j) {
          if ((here.max_gap(j) > 0) != (there.max_gap(j) > 0) ||
              (here.min_gap(j) > 0) != (there.min_gap(j) > 0)) {
            if (!unreliable_noted_) {
              note(fmt::format("curve {}: the {} coefficient is not computed near {} = {:.6g}, "
                               "{} = {:.6g} and wherever a contact changes within {:.1e} of the "
                               "orbit (the map is not smooth there)",
                               curve_, third ? "generalised period doubling" : "cusp",
                               options_.first.name(), p, options_.second.name(), q, reach));
              unreliable_noted_ = true;
            }
            return kNaN;
          }
        }
      }
      const auto phi = [&](const Vector& x) { return maps_.advance(x, p, q, k); };
      const Vector f0 = phi(y);
      const auto second = [&](const Vector& v) {  // B(v, v) = D²φ[v, v]
        return Vector((phi(y + h * v) - 2 * f0 + phi(y - h * v)) / (h * h));
      };
      const Vector Bqq = second(qv);
      if (!third) return 0.5 * pv.dot(Bqq);
      const Vector Cqqq =
          (phi(y + 2 * h * qv) - 2 * phi(y + h * qv) + 2 * phi(y - h * qv) - phi(y - 2 * h * qv)) /
          (2 * h * h * h);
      const Vector r = (Matrix::Identity(n, n) - pt.M).partialPivLu().solve(Bqq);
      // B(q, r) by polarisation: (B(q + r, q + r) − B(q − r, q − r)) / 4.
      const Vector Bqr = (second(qv + r) - second(qv - r)) / 4;
      return pv.dot(Cqqq) / 6 + 0.5 * pv.dot(Bqr);
    } catch (const Error&) {
      return kNaN;
    }
  }

  // The walk of one direction of a curve on the core's loop.
  class Walk : public CurveWalk<CurvePt> {
   public:
    Walk(CurvesRunner& r, const CurvePt& first) : r_(r), first_(first) {}
    bool closed() const { return closed_; }

    std::optional<CurvePt> corrected(const CurvePt& from, const Vector& predicted) override {
      std::optional<CurvePt> next = r_.corrected(predicted, predicted, from.tangent, &from.jacobian,
                                                 r_.options_.max_corrections, 0.0);
      if (!next) return std::nullopt;
      next->tangent = r_.tangent_at(*next, from.tangent);
      if (!next->tangent.allFinite()) return std::nullopt;
      return next;
    }

    std::optional<std::string> stop_before(const CurvePt& from, CurvePt& to, double h,
                                           int points) override {
      if (points > 10 && (to.u - first_.u).norm() < h) {
        closed_ = true;
        return std::string("closed on itself");
      }
      return clip(from, to, h);
    }

    // A step that leaves the rectangle ends on its edge: `to` becomes the curve's point where it
    // crosses the edge it crosses first (located on the arclength to 1e-10 of the range), so the
    // curves end on the figure's frame and no codimension-two point is looked for outside it.
    // Where that point cannot be found (the correction fails between the two, as across a
    // grazing), the walk ends at `from`, the last point inside, and says so.
    std::optional<std::string> clip(const CurvePt& from, CurvePt& to, double h) {
      const double p_range = r_.p_hi_ - r_.p_lo_, q_range = r_.q_hi_ - r_.q_lo_;
      // The four edges as inside-positive distances, scaled by their range.
      const auto inside = [&](const CurvePt& pt, int edge) {
        const double p = r_.system_->p(pt.u), q = r_.system_->q(pt.u);
        switch (edge) {
          case 0: return (r_.q_hi_ - q) / q_range;
          case 1: return (q - r_.q_lo_) / q_range;
          case 2: return (r_.p_hi_ - p) / p_range;
          default: return (p - r_.p_lo_) / p_range;
        }
      };
      int edge = -1;
      double first = 2.0;  // the fraction of the step where the edge is crossed, linearly
      for (int e = 0; e < 4; ++e) {
        const double a = inside(from, e), b = inside(to, e);
        if (a >= 0 && b < 0 && a / (a - b) < first) first = a / (a - b), edge = e;
      }
      if (edge < 0) return std::nullopt;
      const auto trial = [&](double s, const CurvePt& end_a, double sa, const CurvePt& end_b,
                             double sb) -> std::optional<std::pair<CurvePt, double>> {
        const double w = (s - sa) / (sb - sa);
        const Vector guess = (1 - w) * end_a.u + w * end_b.u;
        std::optional<CurvePt> pt =
            r_.corrected(guess, from.u + s * from.tangent, from.tangent, &from.jacobian,
                         r_.options_.max_corrections + 3, 0.0);
        if (!pt) return std::nullopt;
        const double f = inside(*pt, edge);
        return std::pair<CurvePt, double>{std::move(*pt), f};
      };
      const auto small = [&](const CurvePt& end_a, double, const CurvePt& end_b, double) {
        return std::abs(inside(end_a, edge) - inside(end_b, edge)) <= 1e-10;
      };
      ArclengthZero<CurvePt> zero =
          zero_on_arclength(from, inside(from, edge), to, inside(to, edge), h, trial, small);
      if (!zero.located || std::abs(zero.value) > 1e-9) {
        const analysis::SweepParameter& left = edge < 2 ? r_.options_.second : r_.options_.first;
        return fmt::format("left the {} range after {} = {:.10g}, {} = {:.10g}, where the curve "
                           "could not be followed to the range's edge",
                           left.name(), r_.options_.first.name(), r_.system_->p(from.u),
                           r_.options_.second.name(), r_.system_->q(from.u));
      }
      zero.best.tangent = from.tangent;
      to = std::move(zero.best);
      edge_ = edge;
      return std::nullopt;
    }

    std::optional<std::string> accept(CurvePt& from, CurvePt& to, double h,
                                      int /*points*/) override {
      r_.system_->refresh();
      r_.warm_ = to.ritz;
      r_.cross(from, to, h);
      r_.detect(from, to, h);
      r_.emit(to);
      return std::nullopt;
    }

    std::optional<std::string> stop_after(const CurvePt& point, int /*points*/) override {
      const double p = r_.system_->p(point.u), q = r_.system_->q(point.u);
      const double pm = 1e-9 * (r_.p_hi_ - r_.p_lo_), qm = 1e-9 * (r_.q_hi_ - r_.q_lo_);
      // Clipped onto an edge (clip) or past one: which range it left.
      const bool q_out = q > r_.q_hi_ + qm || q < r_.q_lo_ - qm;
      const bool p_out = p > r_.p_hi_ + pm || p < r_.p_lo_ - pm;
      if (edge_ >= 0 || q_out || p_out) {
        const bool left_q = edge_ >= 0 ? edge_ < 2 : q_out;
        return fmt::format("left the {} range at {} = {:.10g}, {} = {:.10g}",
                           (left_q ? r_.options_.second : r_.options_.first).name(),
                           r_.options_.first.name(), p, r_.options_.second.name(), q);
      }
      if (r_.type_ == CurveType::neimark_sacker) {
        const double kappa = point.u(point.u.size() - 1);
        if (std::abs(kappa) > 1) {
          return fmt::format("the multipliers turn real at {} = {:.10g}, {} = {:.10g} (κ = {:.6g}): "
                             "past it the equations describe a neutral saddle, not a bifurcation",
                             r_.options_.first.name(), p, r_.options_.second.name(), q, kappa);
        }
      }
      return std::nullopt;
    }

    double parameter_share(const Vector& tangent) const override {
      const Index n = r_.system_->state_size();
      return std::hypot(tangent(n), tangent(n + 1));
    }
    Index state_size() const override { return r_.system_->state_size(); }

   private:
    CurvesRunner& r_;
    const CurvePt& first_;
    bool closed_ = false;
    int edge_ = -1;  // the edge the last point was clipped onto (clip's numbering), or -1
  };

  // Where the curve crosses the branch's Q between two points, located: a bifurcation of the
  // branch there of the curve's kind lies on this curve (follow() skips it).
  struct Crossing {
    CurveType type;
    int period, spring;
    bool at_largest;
    double p;
    int curve;
  };
  void cross(const CurvePt& a, const CurvePt& b, double h) {
    const double fa = system_->q(a.u) - q0_, fb = system_->q(b.u) - q0_;
    if (fa == 0 || (fa > 0) == (fb > 0)) return;
    const auto trial = [&](double s, const CurvePt& end_a, double sa, const CurvePt& end_b,
                           double sb) -> std::optional<std::pair<CurvePt, double>> {
      const double w = (s - sa) / (sb - sa);
      const Vector guess = (1 - w) * end_a.u + w * end_b.u;
      CurvePt pt;
      if (free_ != nullptr) {
        std::optional<MatrixFreeCurve::Corrected> c = free_->correct(
            guess, a.u + s * a.tangent, a.tangent, 2 * (options_.max_corrections + 3), 0.0);
        if (!c) return std::nullopt;
        pt.u = std::move(c->u);
      } else {
        std::optional<CorrectedPoint> c =
            correct_on_curve(*system_, guess, a.u + s * a.tangent, a.tangent, &a.jacobian,
                             corrector_settings(options_.max_corrections + 3, 0.0, false));
        if (!c) return std::nullopt;
        pt.u = std::move(c->u);
      }
      const double f = system_->q(pt.u) - q0_;
      return std::pair<CurvePt, double>{std::move(pt), f};
    };
    const auto small = [&](const CurvePt& end_a, double sa, const CurvePt& end_b, double sb) {
      return std::abs(system_->p(end_b.u) - system_->p(end_a.u)) <= 1e-9 * p_scale_ &&
             std::abs(sb - sa) <= 1e-6 * std::abs(h);
    };
    const ArclengthZero<CurvePt> zero = zero_on_arclength(a, fa, b, fb, h, trial, small);
    if (zero.located) {
      crossings_.push_back({type_, system_->period(), spring_, at_largest_,
                            system_->p(zero.best.u), curve_});
    }
  }

  CorrectorSettings corrector_settings(int corrections, double polish,
                                       bool jacobian_at_solution) const {
    CorrectorSettings settings;
    settings.chord = chord_;
    settings.corrections = corrections;
    settings.tolerance = options_.shooting.tolerance;
    settings.polish = polish;
    settings.jacobian_at_solution = jacobian_at_solution;
    return settings;
  }

  // The codimension-two points between two consecutive points of the curve.
  void detect(CurvePt& a, CurvePt& b, double h) {
    struct Found {
      std::size_t test;
      ArclengthZero<CurvePt> zero;
    };
    std::vector<Found> found;
    for (std::size_t i = 0; i < tests_.size(); ++i) {
      const double fa = a.tests[i], fb = b.tests[i];
      if (!std::isfinite(fa) || !std::isfinite(fb) || (fa > 0) == (fb > 0)) continue;
      // A pair crosses the circle only where the complex multipliers outside it change in number
      // (the nearest pair's distance also changes sign where pairs meet on the real axis).
      if (tests_[i].kind == Test::Kind::complex_pairs &&
          complex_outside(a.mu) == complex_outside(b.mu)) {
        continue;
      }
      const auto trial = [&](double s, const CurvePt& end_a, double sa, const CurvePt& end_b,
                             double sb) -> std::optional<std::pair<CurvePt, double>> {
        const double w = (s - sa) / (sb - sa);
        const Vector guess = (1 - w) * end_a.u + w * end_b.u;
        const Vector prediction = a.u + s * a.tangent;
        std::optional<CurvePt> pt = corrected(guess, prediction, a.tangent, &a.jacobian,
                                              options_.max_corrections + 3, kLocateResidual);
        if (!pt) return std::nullopt;
        const double f = pt->tests[i];
        return std::pair<CurvePt, double>{std::move(*pt), f};
      };
      const auto small = [&](const CurvePt& end_a, double sa, const CurvePt& end_b, double sb) {
        return std::abs(system_->p(end_b.u) - system_->p(end_a.u)) <= options_.locate_tolerance &&
               std::abs(system_->q(end_b.u) - system_->q(end_a.u)) <= options_.locate_tolerance &&
               std::abs(sb - sa) <= 1e-6 * std::abs(h);
      };
      found.push_back({i, zero_on_arclength(a, fa, b, fb, h, trial, small)});
    }
    std::stable_sort(found.begin(), found.end(), [&](const Found& x, const Found& y) {
      return a.tangent.dot(x.zero.best.u - a.u) < a.tangent.dot(y.zero.best.u - a.u);
    });
    for (const Found& f : found) record(f.test, f.zero, a, b);
  }

  void record(std::size_t index, const ArclengthZero<CurvePt>& zero, const CurvePt& a,
              const CurvePt& b) {
    const Test& test = tests_[index];
    const CurvePt& at = zero.best;
    const double p = system_->p(at.u), q = system_->q(at.u);
    std::string detail;
    if (test.kind == Test::Kind::gap) detail = gap_detail(test.spring, test.at_largest);
    if (type_ == CurveType::grazing) {
      detail = detail.empty() ? "on the grazing of " + gap_detail(spring_, at_largest_)
                              : detail + " and " + gap_detail(spring_, at_largest_);
    }
    if (test.kind == Test::Kind::kappa) detail = fmt::format("κ = {:.10g}", at.u(at.u.size() - 1));
    // A jump of the test function (a multiplier changing identity) is not a zero.
    const bool jump = zero.located && test.kind != Test::Kind::gap &&
                      std::abs(zero.value) >
                          1e-6 * std::max({std::abs(a.tests[index]), std::abs(b.tests[index]),
                                           1e-300});
    if (!zero.located || jump) {
      note(fmt::format("curve {}: a {} point{} between {} = {:.10g} and {:.10g} was detected, "
                       "not located{}",
                       curve_, test.type,
                       test.kind == Test::Kind::gap ? " (" + gap_detail(test.spring, test.at_largest) + ")"
                                                    : std::string(),
                       options_.first.name(), system_->p(a.u), system_->p(b.u),
                       jump ? " (its test function jumps there)" : ""));
      return;
    }
    // On a Neimark–Sacker curve, det(M ∓ I) also vanishes where the pair itself reaches ±1 (κ =
    // ±1): that is the 1:1 or 1:2 resonance, which the κ test records, not a fold or flip of
    // another multiplier alongside the pair.
    if (type_ == CurveType::neimark_sacker &&
        (test.kind == Test::Kind::det_minus || test.kind == Test::Kind::det_plus)) {
      const double kappa = at.u(at.u.size() - 1);
      const double resonance = test.kind == Test::Kind::det_minus ? 1.0 : -1.0;
      if (std::abs(kappa - resonance) <= 1e-6) return;
    }
    // The same point found on another curve already: one row, with both curves.
    const double pm = 1e-6 * (p_hi_ - p_lo_), qm = 1e-6 * (q_hi_ - q_lo_);
    for (Codim2Point& c : result_.codim2) {
      if (c.type == test.type && std::abs(c.p - p) <= pm && std::abs(c.q - q) <= qm) {
        if (std::find(c.curves.begin(), c.curves.end(), curve_) == c.curves.end()) {
          c.curves.push_back(curve_);
        }
        return;
      }
    }
    Codim2Point c;
    c.type = test.type;
    c.p = p;
    c.q = q;
    c.curves = {curve_};
    c.detail = detail;
    c.state = at.u.head(system_->state_size());
    c.period = system_->period();
    result_.codim2.push_back(c);
    if (observer_ != nullptr) observer_->codim2(c);
  }

  void emit(CurvePt& pt) {
    CurvePointRecord r;
    r.curve = curve_;
    r.type = type_;
    r.p = system_->p(pt.u);
    r.q = system_->q(pt.u);
    r.period = system_->period();
    r.spring = type_ == CurveType::grazing ? spring_ : -1;
    r.at_largest_gap = at_largest_;
    r.multiplier = system_->multiplier(pt.mu, pt.u);
    r.kappa = type_ == CurveType::neimark_sacker ? pt.u(pt.u.size() - 1) : kNaN;
    r.state = pt.u.head(system_->state_size());
    r.amplitude = profile_of(pt).amplitude;
    if (observer_ != nullptr) observer_->point(r);
    result_.points.push_back(std::move(r));
  }

  void note(std::string message) {
    if (observer_ != nullptr) observer_->note(message);
    result_.notes.push_back(std::move(message));
  }

  const analysis::PointModel& model_;
  const CurvesOptions& options_;
  CurvesObserver* observer_;
  CurvesResult& result_;
  PlaneMaps maps_;
  double p_scale_, q_scale_;
  double p_lo_ = 0, p_hi_ = 0, q_lo_ = 0, q_hi_ = 0, q0_ = 0;
  StepControl steps_;
  bool chord_ = false;
  // The curve being followed.
  CurveSystem* system_ = nullptr;
  MatrixFreeCurve* free_ = nullptr;  // the same system where it is matrix-free
  Eigen::MatrixXcd warm_;              // matrix-free: the last accepted point's Ritz vectors
  CurveType type_ = CurveType::fold;
  int curve_ = 0;
  int spring_ = -1;
  bool at_largest_ = true;
  std::vector<Test> tests_;
  std::vector<Crossing> crossings_;  // of the branch's Q, by every curve so far
  int springs_ = 0;
  bool unreliable_noted_ = false;
  bool untrusted_noted_ = false;  // a note said where the multipliers could not be trusted
};

}  // namespace

CurvesResult follow_bifurcation_curves(const analysis::PointModel& model,
                                       const std::vector<Bifurcation>& starts,
                                       const CurvesOptions& options, CurvesObserver* observer) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  for (const auto& parameter : {options.first, options.second}) {
    if (!model.has(parameter, &why)) throw InputError(why);
  }
  const double q0 = model.value(options.second);
  const double lo = std::min(options.q_from, options.q_to);
  const double hi = std::max(options.q_from, options.q_to);
  if (!(q0 >= lo && q0 <= hi)) {
    throw InputError(fmt::format("the branch's {} = {} lies outside the {} range {}:{}: the curves "
                                 "start on the branch",
                                 options.second.name(), q0, options.second.name(), options.q_from,
                                 options.q_to));
  }
  for (const double q : {options.q_from, options.q_to}) {
    if (!model.accepts(options.second, q, &why)) {
      throw InputError(fmt::format("{} range {}:{}: at {} = {}: {}", options.second.name(),
                                   options.q_from, options.q_to, options.second.name(), q, why));
    }
  }
  CurvesResult result;
  CurvesRunner runner(model, options, observer, result);
  runner.run(starts);
  return result;
}

}  // namespace pwl::orbits
