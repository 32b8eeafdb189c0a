#include "orbits/matrix_free_curve.hpp"

#include "orbits/leading_multipliers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pwl::orbits::curves_detail {

namespace {
// GMRES's relative residual for a tangent (as the one-parameter continuation asks).
constexpr double kTangentTolerance = 1e-10;
}  // namespace

std::optional<MatrixFreeCurve::Corrected> MatrixFreeCurve::correct(const Vector& guess,
                                                                   const Vector& prediction,
                                                                   const Vector& tau,
                                                                   int iterations, double polish) {
  const CurveSystem& system = curve();
  detail::NewtonKrylovSystem newton;
  newton.admissible = [&system](const Vector& u) { return system.admissible(u); };
  newton.scale = [&system](const Vector& u) { return system.scale(u); };
  newton.residual = [this](const Vector& u) { return residual_norm(u); };
  newton.step = [&](const Vector& u, double arc, double eta) {
    return bordered_solve(u, tau, arc, eta);
  };
  return detail::newton_krylov(newton, guess, prediction, tau, iterations, polish, tolerance_);
}

std::function<Vector(const Vector&)> monodromy_products(PlaneMaps& maps, const Vector& y, double p,
                                                        double q, int period) {
  StroboscopicMap& map = maps.at(p, q);
  CurvesResult& counts = maps.result();
  return [&map, &counts, y, period](const Vector& v) -> Vector {
    Matrix V = v;
    map.advance(y, period, V);
    ++counts.krylov_products;
    return V.col(0);
  };
}

Vector MatrixFreeCurve::tangent(const Vector& u, const Vector& previous) {
  const std::optional<Vector> z = bordered_solve(u, previous, std::nullopt, kTangentTolerance);
  const double norm = z ? z->norm() : 0.0;
  if (!(norm > 0) || !std::isfinite(norm)) {
    return Vector::Constant(u.size(), std::numeric_limits<double>::quiet_NaN());
  }
  const Vector t = *z / norm;
  return t.dot(previous) < 0 ? Vector(-t) : t;
}

FloquetMultipliers leading_multipliers(PlaneMaps& maps, const Vector& y, double p, double q,
                                       int period, const detail::OpenStructurePreconditioner* open,
                                       const Eigen::MatrixXcd* warm, Eigen::MatrixXcd* ritz,
                                       double margin) {
  StroboscopicMap& map = maps.at(p, q);
  ArnoldiOptions arnoldi = maps.options().shooting.arnoldi;
  arnoldi.block = map.tangent_block();
  arnoldi.margin = std::max(arnoldi.margin, margin);
  CurvesResult& counts = maps.result();
  return detail::leading_multipliers(
      [&](Matrix& v) {
        map.advance(y, period, v);
        counts.arnoldi_products += v.cols();
      },
      y.size(), arnoldi, open, warm, ritz);
}

CurvePreconditioner::CurvePreconditioner(PlaneMaps& maps, int period, double p0, double q0,
                                         double shift)
    : maps_(maps), period_(period) {
  if (maps.options().shooting.precondition) {
    StroboscopicMap& map = maps.at(p0, q0);
    open_.emplace(map.structure(), period * map.forcing_period(), shift);
  }
}

const detail::OpenStructurePreconditioner* CurvePreconditioner::at(double p, double q,
                                                                   std::optional<double> kappa) {
  if (!open_ || !open_->available()) return nullptr;
  const double tau = period_ * maps_.at(p, q).forcing_period();
  if (tau != open_->time()) open_->retime(tau);
  open_->set_quadratic(kappa);
  return &*open_;
}

}  // namespace pwl::orbits::curves_detail
