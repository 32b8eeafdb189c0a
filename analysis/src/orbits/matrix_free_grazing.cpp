#include "orbits/matrix_free_grazing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "orbits/bordered_krylov.hpp"
#include "pwl/errors.hpp"

namespace pwl::orbits::curves_detail {

namespace {
// The relative step of the central differences in a parameter (as the dense system takes them).
constexpr double kParameterStep = 1e-6;
}  // namespace

MatrixFreeGrazing::MatrixFreeGrazing(PlaneMaps& maps, int period, Index n, double p_scale,
                                     double q_scale, int spring, bool at_largest, double p0,
                                     double q0)
    : GrazingSystem(maps, period, n, p_scale, q_scale, spring, at_largest),
      MatrixFreeCurve(maps.options().shooting.tolerance),
      open_(maps, period, p0, q0, 1.0),
      space_(maps.options().shooting.gmres_recycled, maps.options().shooting.gmres_reform) {}

bool MatrixFreeGrazing::residuals(const Vector& u, Linearised& l) {
  if (last_at_.size() == u.size() && last_at_ == u) {
    l = last_;
    return true;
  }
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  maps_.pin(p, q);
  try {
    l.F = maps_.advance(y, p, q, period_) - y;
    const GapExtreme e = maps_.gap_extreme(y, p, q, period_, spring_, at_largest_);
    l.gamma = e.value;
    const double end = period_ * maps_.at(p, q).forcing_period();
    l.t = std::clamp(maps_.on_grid(p, q, e.time), 0.0, end);
    // Last on this map: the state at t records the first arc, which the products replay.
    l.at_t = maps_.flow(y, p, q, l.t);
  } catch (const Error&) {
    return false;
  }
  if (!(l.F.allFinite() && std::isfinite(l.gamma) && l.at_t.allFinite())) return false;
  last_ = l;
  last_at_ = u;
  return true;
}

bool MatrixFreeGrazing::linearise(const Vector& u, Linearised& l) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const Index dofs = n_ / 2;
  try {
    const double dp = kParameterStep * std::max(1.0, std::abs(p));
    const double dq = kParameterStep * std::max(1.0, std::abs(q));
    l.B = parameter_columns(u);
    // γ at fixed t (the envelope theorem): the gap at t of the perturbed structures.
    const Vector w = maps_.at(p, q).structure().spring_directions().col(spring_);
    const auto gap_at = [&](double pp, double qq) {
      const double gap = maps_.at(pp, qq).structure().spring_gaps()(spring_);
      return w.dot(maps_.flow(y, pp, qq, l.t).head(dofs)) - gap;
    };
    l.gamma_p = (gap_at(p + dp, q) - gap_at(p - dp, q)) * (p_scale_ / (2 * dp));
    l.gamma_q = (gap_at(p, q + dq) - gap_at(p, q - dq)) * (q_scale_ / (2 * dq));
  } catch (const Error&) {
    return false;
  }
  return l.B.allFinite() && std::isfinite(l.gamma_p) && std::isfinite(l.gamma_q);
}

bool MatrixFreeGrazing::solve(const Vector& u, const Linearised& l, const Vector& tau,
                              const Vector& r, const Vector& rho, Vector& delta,
                              double tolerance) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const Index dofs = n_ / 2;
  const ShootingOptions& shooting = maps_.options().shooting;
  try {
    StroboscopicMap& second = maps_.second_at(p, q);
    StroboscopicMap& first = maps_.at(p, q);
    const detail::OpenStructurePreconditioner* open = open_.at(p, q);
    const double end = period_ * first.forcing_period();
    const bool whole_first = l.t >= end * (1 - 1e-12);
    const Vector w = first.structure().spring_directions().col(spring_);
    CurvesResult& counts = maps_.result();
    // [M v; ∇γᵀ v]: Φ(t) v, then on from t to the period's end.
    const auto product = [&](const Vector& v) -> Vector {
      Matrix V = v;
      if (l.t > 0) first.flow(y, 0.0, whole_first ? end : l.t, &V);
      const double row = w.dot(V.col(0).head(dofs));
      if (!whole_first) second.flow(l.at_t, l.t, end, &V);
      ++counts.krylov_products;
      Vector out(n_ + 1);
      out << V.col(0), row;
      return out;
    };
    // The gap's row: known only by its products, but at t = 0 it is the gap direction itself.
    Matrix C = Matrix::Zero(n_, 2);
    C.col(1) = tau.head(n_);
    const bool row_known = !(l.t > 0);
    if (row_known) C.col(0).head(dofs) = w;
    Matrix D(2, 2);
    D << l.gamma_p, l.gamma_q, tau(n_), tau(n_ + 1);
    const detail::BorderedKrylov system(product, open, l.B, C, D, row_known ? 0 : 1);
    Vector x, s;
    // Each step is a new operator: the space is dropped, or its image formed again
    // (ShootingOptions::gmres_reform).
    space_.operator_changed();
    system.solve(r, rho, x, s, tolerance, shooting.gmres_dimension, shooting.gmres_restarts,
                 &space_);
    delta.resize(n_ + 2);
    delta << x, s;
  } catch (const Error&) {
    return false;
  }
  return delta.allFinite();
}

std::optional<double> MatrixFreeGrazing::residual_norm(const Vector& u) {
  Linearised l;
  if (!residuals(u, l)) return std::nullopt;
  return std::max(l.F.lpNorm<Eigen::Infinity>(), std::abs(l.gamma));
}

std::optional<Vector> MatrixFreeGrazing::bordered_solve(const Vector& u, const Vector& tau,
                                                        std::optional<double> arc,
                                                        double tolerance) {
  Linearised l;
  if (!residuals(u, l) || !linearise(u, l)) return std::nullopt;
  Vector rho(2);
  if (arc) {
    rho << -l.gamma, -*arc;
  } else {
    rho << 0.0, 1.0;
  }
  Vector delta;
  if (!solve(u, l, tau, arc ? Vector(-l.F) : Vector(Vector::Zero(n_)), rho, delta, tolerance)) {
    return std::nullopt;
  }
  return delta;
}

FloquetMultipliers MatrixFreeGrazing::multipliers(const Vector& u, const Eigen::MatrixXcd* warm,
                                                  Eigen::MatrixXcd* ritz) {
  return leading_multipliers(maps_, u.head(n_), p(u), q(u), period_, open_.at(p(u), q(u)), warm,
                             ritz);
}

}  // namespace pwl::orbits::curves_detail
