#include "pwl/orbits/arclength_continuation.hpp"

#include <Eigen/LU>
#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl::orbits {

std::string corrector_name(Corrector corrector) {
  switch (corrector) {
    case Corrector::automatic: return "automatic";
    case Corrector::chord: return "chord";
    case Corrector::newton: return "newton";
  }
  return "?";
}

Corrector parse_corrector(const std::string& name) {
  for (Corrector c : {Corrector::automatic, Corrector::chord, Corrector::newton}) {
    if (corrector_name(c) == name) return c;
  }
  throw InputError(
      fmt::format("corrector = \"{}\" is not known; use automatic, chord or newton", name));
}

Matrix bordered_jacobian(const Matrix& jacobian, const Vector& row) {
  const Index m = jacobian.rows();
  Matrix A(m + 1, m + 1);
  A.topRows(m) = jacobian;
  A.bottomRows(1) = row.transpose();
  return A;
}

Vector curve_tangent(const Matrix& jacobian, const Vector& previous) {
  const Index n = jacobian.cols();
  Vector rhs = Vector::Zero(n);
  rhs(n - 1) = 1.0;
  Vector z = Eigen::PartialPivLU<Matrix>(bordered_jacobian(jacobian, previous)).solve(rhs);
  z /= z.norm();
  if (z.dot(previous) < 0) z = -z;
  return z;
}

namespace {
// A step of the chord corrector must shrink the residual at least this much for the Jacobian it
// used to be kept, and a corrector takes at most kChordIterations steps per Jacobian allowed.
constexpr double kChordContraction = 0.25;
constexpr int kChordIterations = 3;
}  // namespace

std::optional<CorrectedPoint> correct_on_curve(DefiningSystem& system, const Vector& guess,
                                               const Vector& prediction, const Vector& tau,
                                               const Matrix* start,
                                               const CorrectorSettings& settings, long* stalls) {
  const double tolerance = settings.tolerance;
  double polish = settings.polish;
  if (!(polish > 0.0) || polish > tolerance) polish = tolerance;
  const bool chord = settings.chord;
  const Index n = guess.size();
  const Index last = n - 1;
  CorrectedPoint pt;
  pt.u = guess;
  Eigen::PartialPivLU<Matrix> lu;
  bool factored = chord && start != nullptr;
  if (factored) lu.compute(bordered_jacobian(*start, tau));
  double previous = std::numeric_limits<double>::infinity();
  Vector last_u = pt.u;  // the iterate whose residual is `previous`
  Vector G;
  Matrix J;
  // G at the iterate, with the Jacobian there or without; false where it cannot be evaluated.
  const auto evaluate = [&](bool with_jacobian) {
    return system.evaluate(pt.u, G, with_jacobian ? &J : nullptr) && G.allFinite();
  };
  // The arclength constraint, the state's and the first parameters' part summed first.
  const auto constraint_at = [&] {
    return tau.head(last).dot(pt.u.head(last) - prediction.head(last)) +
           tau(last) * (pt.u(last) - prediction(last));
  };
  // While polishing: the iterate with the smallest residual among those already within the
  // tolerance (and on the constraint). Returned when polishing ends on a worse one or runs out
  // of Jacobians or steps, so that polishing never loses a point the tolerance accepts.
  struct Within {
    Vector u;
    double res = 0.0;
    int it = 0;
  };
  std::optional<Within> within;
  const auto fall_back = [&]() -> std::optional<CorrectedPoint> {
    if (!within) return std::nullopt;
    pt.u = within->u;
    pt.iterations = within->it;
    pt.residual = within->res;
    pt.jacobian.resize(0, 0);
    if (!settings.jacobian_at_solution) return pt;
    if (!evaluate(true)) return std::nullopt;
    pt.residual = G.lpNorm<Eigen::Infinity>();
    pt.jacobian = std::move(J);
    return pt;
  };
  for (int it = 0; it <= kChordIterations * settings.corrections; ++it) {
    // The Jacobian is formed here when there is none yet or the last chord step did not
    // contract; otherwise only G is evaluated.
    bool formed = !factored || !chord;
    if (!evaluate(formed)) return fall_back();
    double res = G.lpNorm<Eigen::Infinity>();
    double constraint = constraint_at();
    const double scale = system.scale(pt.u);
    const bool on_constraint = std::abs(constraint) <= 1e-12 * scale;
    const bool closed = res <= polish * scale ||
                        (res <= tolerance * scale && !(res <= kChordContraction * previous));
    if (closed && on_constraint && within && within->res < res) return fall_back();
    if (polish < tolerance && res <= tolerance * scale && on_constraint &&
        !(within && within->res <= res)) {
      within = Within{pt.u, res, it};
    }
    if (closed && on_constraint) {
      pt.iterations = it;
      if (!formed && !settings.jacobian_at_solution) {
        pt.residual = res;
        pt.jacobian.resize(0, 0);
        return pt;
      }
      // The Jacobian at the point (the same evaluation, with it).
      if (!formed && !evaluate(true)) return std::nullopt;
      pt.residual = G.lpNorm<Eigen::Infinity>();
      pt.jacobian = std::move(J);
      return pt;
    }
    if (!formed && !(res <= kChordContraction * previous)) {
      // The chord step stalled: the Jacobian here, or back where the step started if it made
      // the residual larger.
      if (!(res <= previous)) {
        pt.u = last_u;
        constraint = constraint_at();
      }
      if (!evaluate(true)) return fall_back();
      res = G.lpNorm<Eigen::Infinity>();
      formed = true;
      if (stalls != nullptr) ++*stalls;
    }
    if (formed) {
      if (pt.formed++ >= settings.corrections) return fall_back();
      lu.compute(bordered_jacobian(J, tau));
      factored = true;
    }
    previous = res;
    last_u = pt.u;
    Vector rhs(n);
    rhs.head(last) = -G;
    rhs(last) = -constraint;
    const Vector d = lu.solve(rhs);
    if (!d.allFinite()) return fall_back();
    pt.u += d;
    if (!system.admissible(pt.u)) return fall_back();
  }
  return fall_back();
}

bool walk_settings_valid(double initial_step, double min_step, double max_step, int max_points,
                         int max_corrections, double locate_tolerance, std::string* why) {
  for (const auto& [name, value] : {std::pair{"initial step", initial_step},
                                    std::pair{"min step", min_step},
                                    std::pair{"max step", max_step}}) {
    if (!(value >= 0) || !std::isfinite(value)) {
      *why = fmt::format("{} = {} must be >= 0 and finite (0: the default)", name, value);
      return false;
    }
  }
  if (max_points < 2) {
    *why = fmt::format("max points = {} must be >= 2", max_points);
    return false;
  }
  if (max_corrections < 2) {
    *why = fmt::format("max corrections = {} must be >= 2", max_corrections);
    return false;
  }
  if (!(locate_tolerance > 0) || !std::isfinite(locate_tolerance)) {
    *why = fmt::format("locate tolerance = {} must be positive and finite", locate_tolerance);
    return false;
  }
  return true;
}

}  // namespace pwl::orbits
