#include "orbits/matrix_free_curve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pwl::orbits::curves_detail {

detail::NewtonKrylovSystem newton_system(const CurveSystem& curve) {
  detail::NewtonKrylovSystem system;
  system.admissible = [&curve](const Vector& u) { return curve.admissible(u); };
  system.scale = [&curve](const Vector& u) { return curve.scale(u); };
  return system;
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

Vector unit_tangent(const Vector& z, const Vector& previous) {
  const double norm = z.norm();
  if (!(norm > 0) || !std::isfinite(norm)) {
    return Vector::Constant(z.size(), std::numeric_limits<double>::quiet_NaN());
  }
  const Vector t = z / norm;
  return t.dot(previous) < 0 ? Vector(-t) : t;
}

FloquetMultipliers leading_multipliers(PlaneMaps& maps, const Vector& y, double p, double q,
                                       int period, const Eigen::MatrixXcd* warm,
                                       Eigen::MatrixXcd* ritz, double margin) {
  StroboscopicMap& map = maps.at(p, q);
  ArnoldiOptions arnoldi = maps.options().shooting.arnoldi;
  arnoldi.block = map.tangent_block();
  arnoldi.margin = std::max(arnoldi.margin, margin);
  CurvesResult& counts = maps.result();
  return leading_floquet_multipliers(
      [&](Matrix& v) {
        map.advance(y, period, v);
        counts.arnoldi_products += v.cols();
      },
      y.size(), arnoldi, warm, ritz);
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
