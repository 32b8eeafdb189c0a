#include "orbits/newton_krylov.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pwl::orbits::detail {

std::optional<NewtonKrylovPoint> newton_krylov(const NewtonKrylovSystem& system,
                                               const Vector& guess, const Vector& prediction,
                                               const Vector& tau, int iterations, double polish,
                                               double tolerance_rel) {
  Vector u = guess;
  std::optional<NewtonKrylovPoint> best;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    if (!u.allFinite() || !system.admissible(u)) break;
    const std::optional<double> residual = system.residual(u);
    if (!residual || !std::isfinite(*residual)) break;
    const double res = *residual;
    const double scale = system.scale(u);
    const double arc = tau.dot(u - prediction);
    const double tolerance = tolerance_rel * scale;
    if (res <= tolerance && std::abs(arc) <= tolerance) {
      if (!best || res < best->residual) best = NewtonKrylovPoint{u, res, it};
      if (polish <= 0 || res <= polish * scale || res > 0.25 * previous) break;
    } else if (res > 4 * previous) {
      break;  // diverging
    }
    if (it == iterations) break;
    const double target = polish > 0 ? std::min(tolerance, polish * scale) : tolerance;
    const double eta = std::clamp(0.5 * target / std::max(res, 1e-300), 1e-10, 1e-2);
    const std::optional<Vector> delta = system.step(u, arc, eta);
    if (!delta) break;
    u += *delta;
    previous = res;
  }
  return best;
}

}  // namespace pwl::orbits::detail
