// The step guard (step_guard.hpp): ω_max with every gap spring touching, and a fixed step judged
// against its method's row of the method table.
#include "pwl/integrators/step_guard.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// K_all = K + W K2 W^T (every gap spring touching), sparse.
SparseMatrix touching_stiffness(const GapStructure& s) {
  const SparseMatrix W = s.spring_directions_sparse();
  const Vector k = s.spring_stiffnesses();
  SparseMatrix springs = W * k.asDiagonal() * SparseMatrix(W.transpose());
  return SparseMatrix(s.stiffness + springs);
}

// λ_max(A, M) for symmetric A (positive semidefinite) and M (positive definite), dense.
double largest_generalized_eigenvalue(const SparseMatrix& a, const Matrix& mass) {
  if (a.nonZeros() == 0) return 0.0;
  Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> solver(Matrix(a), mass,
                                                          Eigen::EigenvaluesOnly);
  if (solver.info() != Eigen::Success) {
    throw InputError("contact_frequency: the generalized eigenvalue problem (K + W K2 W^T, M) did "
                     "not converge (is the mass matrix positive definite?)");
  }
  return std::max(0.0, solver.eigenvalues().maxCoeff());
}

// Gershgorin's bound of λ_max(A, M): on M^{-1/2} A M^{-1/2} (row i: Σ_j |A_ij| / √(m_i m_j)) for a
// diagonal M, max_i Σ_j |A_ij| over min_i (M_ii - Σ_{j≠i} |M_ij|) otherwise.
double gershgorin_bound(const SparseMatrix& a, const SparseMatrix& mass) {
  const Index n = mass.rows();
  bool diagonal = true;
  Vector diag = Vector::Zero(n), off = Vector::Zero(n);
  for (Index c = 0; c < mass.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(mass, c); it; ++it) {
      if (it.row() == it.col()) {
        diag[it.row()] += it.value();
      } else if (it.value() != 0.0) {
        diagonal = false;
        off[it.row()] += std::abs(it.value());
      }
    }
  }
  Vector rows = Vector::Zero(n);
  for (Index c = 0; c < a.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(a, c); it; ++it) {
      const double scale = diagonal ? std::sqrt(diag[it.row()] * diag[it.col()]) : 1.0;
      rows[it.row()] += std::abs(it.value()) / scale;
    }
  }
  const double largest = n > 0 ? rows.maxCoeff() : 0.0;
  if (diagonal) return largest;
  const double smallest_mass = (diag - off).minCoeff();
  if (!(smallest_mass > 0.0)) {
    throw InputError(fmt::format(
        "contact_frequency: the mass matrix of {} degrees of freedom is not diagonally dominant "
        "(Gershgorin's lower bound of its smallest eigenvalue is {:.3g}), so ω_max cannot be "
        "bounded cheaply; the dense estimate covers up to {} degrees of freedom",
        n, smallest_mass, kDenseFrequencyDofs));
  }
  return largest / smallest_mass;
}

std::string fixed(double v) { return fmt::format("{:.3g}", v); }

// Adaptive rows: a tolerance looser than this draws a warning. Measured by `pwl bench stability
// --alpha 3,10,30,100,1000 --tol 1e-3,1e-4,1e-5,1e-6` on figure 4a's chain over 200 periods:
// at 1e-3 every Runge-Kutta row fails somewhere (missed contacts, kink-located, for α >= 30; the
// wrong period, plain, for α <= 10), at 1e-4 plain dopri5 gets the period wrong for α <= 10 and
// the kink-located rows miss contacts at α = 1000; at 1e-5 and 1e-6 none fails.
constexpr double kLooseTolerance = 1e-5;

}  // namespace

ContactFrequency contact_frequency(const GapStructure& structure) {
  structure.validate();
  ContactFrequency f;
  const SparseMatrix stiffness = touching_stiffness(structure);
  double k_max = 0.0, c_max = 0.0;
  if (structure.dofs() <= kDenseFrequencyDofs) {
    const Matrix mass(structure.mass);
    k_max = largest_generalized_eigenvalue(stiffness, mass);
    c_max = largest_generalized_eigenvalue(structure.damping, mass);
  } else {
    f.bound = true;
    k_max = gershgorin_bound(stiffness, structure.mass);
    c_max = gershgorin_bound(structure.damping, structure.mass);
  }
  f.undamped = std::sqrt(k_max);
  f.damping_rate = c_max;
  f.omega_max = std::max(f.undamped, f.damping_rate);
  return f;
}

StepCheck check_step(const GapStructure& structure, const MethodSettings& settings,
                     double period) {
  std::string why;
  if (!settings.is_valid(structure, &why)) throw InputError(why);
  if (!(period >= 0.0) || !std::isfinite(period)) {
    throw InputError(fmt::format("check_step: period = {} must be finite and >= 0 (0: none)",
                                 period));
  }
  const MethodTraits& row = method_traits(settings.method);
  StepCheck c;
  c.omega_max = contact_frequency(structure).omega_max;
  c.largest_step = c.largest_accepted_step = kInfinity;
  if (row.adaptive && settings.tolerance > kLooseTolerance) {
    c.verdict = StepVerdict::warning;
    c.message = fmt::format(
        "{}: tolerance {} is loose for gap springs: pwl bench stability finds dopri5 and rkf78 "
        "at tolerances 1e-3 and 1e-4 missing contacts or settling on the wrong regime (the paper's "
        "chain, α from 3 to 1000, kink-located or not), and none at 1e-5 or tighter; use a "
        "tolerance of at most {:g}",
        row.name, settings.tolerance, kLooseTolerance);
    return c;
  }
  if (!(row.step_limit > 0.0)) return c;  // no step to guard (step_guard.hpp)

  c.step = settings.step;
  c.warning_limit = row.step_warning;
  c.refusal_limit = row.step_limit;
  c.step_argument = settings.step * c.omega_max;
  if (c.omega_max > 0.0) {
    c.largest_step = row.step_warning / c.omega_max;
    c.largest_accepted_step = row.step_limit / c.omega_max;
  }
  if (period > 0.0 && std::isfinite(c.largest_step)) {
    c.steps_per_period = static_cast<long>(std::ceil(period / c.largest_step));
    // Rounding: T / N must not exceed the largest step.
    while (period / static_cast<double>(c.steps_per_period) > c.largest_step) ++c.steps_per_period;
  }
  if (c.step_argument <= row.step_warning) return c;

  c.verdict = c.step_argument > row.step_limit ? StepVerdict::refusal : StepVerdict::warning;
  const std::string use =
      c.steps_per_period > 0
          ? fmt::format("a step of at most {} (η ω_max = {}), {} steps per forcing period of {} or more",
                        fixed(c.largest_step), fixed(row.step_warning), c.steps_per_period,
                        fixed(period))
          : fmt::format("a step of at most {} (η ω_max = {})", fixed(c.largest_step),
                        fixed(row.step_warning));
  if (c.refused()) {
    c.message = fmt::format(
        "{}: step = {} is too long for the stiffest contact: η ω_max = {} (ω_max = {}, the "
        "highest frequency with every gap spring touching) exceeds the {}'s limit {} (beyond "
        "it, pwl bench stability finds the {} missing contacts or blowing up); use {}, or a "
        "method without a fixed step (exact for a small structure, or rkf78 with "
        "locate_kinks)",
        row.name, fixed(settings.step), fixed(c.step_argument), fixed(c.omega_max), row.label,
        fixed(row.step_limit), row.label, use);
  } else {
    c.message = fmt::format(
        "{}: step = {} resolves the stiffest contact poorly: η ω_max = {} (ω_max = {}, the "
        "highest frequency with every gap spring touching) exceeds {}, beyond which the {}'s "
        "error grows quickly (fewer than {:.0f} steps per period of that contact; refused "
        "beyond {}); use {}",
        row.name, fixed(settings.step), fixed(c.step_argument), fixed(c.omega_max),
        fixed(row.step_warning), row.label, 2.0 * std::numbers::pi / row.step_warning,
        fixed(row.step_limit), use);
  }
  return c;
}

}  // namespace pwl
