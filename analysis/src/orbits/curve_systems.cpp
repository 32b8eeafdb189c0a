#include "curve_systems.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "pwl/errors.hpp"

namespace pwl::orbits::curves_detail {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Relative steps of the central differences: in a parameter (∂F/∂p, as the one-parameter
// continuation takes it) and along a state direction (derivatives of the monodromy: its error is
// the step squared against the third derivative, which a piecewise-linear map keeps small between
// contact changes, and rounding over the step).
constexpr double kParameterStep = 1e-6;
constexpr double kStateStep = 1e-5;
}  // namespace

PlaneMaps::PlaneMaps(const analysis::PointModel& model, const CurvesOptions& options,
                     CurvesResult& result)
    : model_(model), options_(options), result_(result) {}

StroboscopicMap& PlaneMaps::cached(std::map<std::pair<double, double>, StroboscopicMap>& cache,
                                   std::size_t most, double p, double q) {
  const auto key = std::make_pair(p, q);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  if (cache.size() > most) {
    // The pinned map's node is taken out and put back: the map itself (and what it recorded)
    // stays where it is.
    auto kept = pinned_ ? cache.extract(*pinned_) : decltype(cache.extract(key)){};
    cache.clear();
    if (kept) cache.insert(std::move(kept));
  }
  const analysis::PointModel point = model_.with(options_.first, p).with(options_.second, q);
  return cache
      .emplace(key, StroboscopicMap(point.point_case(), options_.method, options_.steps_per_period))
      .first->second;
}

StroboscopicMap& PlaneMaps::at(double p, double q) { return cached(maps_, 16, p, q); }

bool PlaneMaps::accepts(double p, double q) const {
  std::string why;
  return std::isfinite(p) && std::isfinite(q) && model_.accepts(options_.first, p, &why) &&
         model_.with(options_.first, p).accepts(options_.second, q, &why);
}

Vector PlaneMaps::advance(const Vector& y, double p, double q, int period, Matrix* tangent) {
  StroboscopicMap& map = at(p, q);
  if (tangent == nullptr) {
    ++result_.integrations;
    return map.advance(y, period);
  }
  if (tangent->cols() == y.size()) {
    ++result_.monodromies;
  } else {
    ++result_.integrations;
  }
  return map.advance(y, period, *tangent);
}

OrbitProfile PlaneMaps::profile(const Vector& y, double p, double q, int period) {
  ++result_.integrations;
  return orbit_profile(at(p, q), y, period, options_.profile_samples);
}

GapExtreme PlaneMaps::gap_extreme(const Vector& y, double p, double q, int period, int spring,
                                  bool largest) {
  ++result_.integrations;
  return orbits::gap_extreme(at(p, q), y, period, spring, largest, options_.profile_samples);
}

StroboscopicMap& PlaneMaps::second_at(double p, double q) { return cached(seconds_, 4, p, q); }

double PlaneMaps::on_grid(double p, double q, double t) {
  StroboscopicMap& map = at(p, q);
  if (!method_traits(map.settings().method).fixed_grid) return t;
  const double h = map.forcing_period() / map.steps_per_period();
  return std::round(t / h) * h;
}

Vector PlaneMaps::flow(const Vector& y, double p, double q, double t, Matrix* tangent) {
  StroboscopicMap& map = at(p, q);
  t = on_grid(p, q, t);
  if (!(t > 0)) return y;
  if (tangent != nullptr && tangent->cols() == y.size()) {
    ++result_.monodromies;
  } else {
    ++result_.integrations;
  }
  return map.flow(y, 0.0, t, tangent);
}

bool CurveSystem::admissible(const Vector& u) const {
  return u.allFinite() && maps_.accepts(p(u), q(u));
}

Vector CurveSystem::unknowns(const Vector& y, double p, double q, std::optional<double> aux) const {
  Vector u(n_ + 2 + (aux ? 1 : 0));
  u.head(n_) = y;
  u(n_) = p / p_scale_;
  u(n_ + 1) = q / q_scale_;
  if (aux) u(n_ + 2) = *aux;
  return u;
}

bool CurveSystem::orbit_rows(const Vector& u, Vector& F, Matrix* jacobian, bool monodromy) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  try {
    if (monodromy || jacobian != nullptr) {
      if (M_at_.size() != u.size() || M_at_ != u) {
        Matrix M = Matrix::Identity(n_, n_);
        const Vector end = maps_.advance(y, p, q, period_, &M);
        M_ = std::move(M);
        M_at_ = u;
        F_ = end - y;
        F_at_ = u;
      }
      F = F_;
    } else if (F_at_.size() == u.size() && F_at_ == u) {
      F = F_;
    } else {
      F = maps_.advance(y, p, q, period_) - y;
      F_ = F;
      F_at_ = u;
    }
    if (!F.allFinite()) return false;
    if (jacobian != nullptr) {
      jacobian->topRows(n_).setZero();
      jacobian->topLeftCorner(n_, n_) = M_ - Matrix::Identity(n_, n_);
      jacobian->block(0, n_, n_, 2) = parameter_columns(u);
    }
  } catch (const Error&) {
    return false;
  }
  return true;
}

Matrix CurveSystem::parameter_columns(const Vector& u) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const double dp = kParameterStep * std::max(1.0, std::abs(p));
  const double dq = kParameterStep * std::max(1.0, std::abs(q));
  Matrix B(n_, 2);
  B.col(0) = (maps_.advance(y, p + dp, q, period_) - maps_.advance(y, p - dp, q, period_)) *
             (p_scale_ / (2 * dp));
  B.col(1) = (maps_.advance(y, p, q + dq, period_) - maps_.advance(y, p, q - dq, period_)) *
             (q_scale_ / (2 * dq));
  return B;
}

Matrix CurveSystem::monodromy_derivative(const Vector& u, const Vector& v) {
  const Vector y = u.head(n_);
  const double eps =
      kStateStep * std::max(1.0, y.lpNorm<Eigen::Infinity>()) / v.lpNorm<Eigen::Infinity>();
  Matrix plus = Matrix::Identity(n_, n_), minus = Matrix::Identity(n_, n_);
  maps_.advance(y + eps * v, p(u), q(u), period_, &plus);
  maps_.advance(y - eps * v, p(u), q(u), period_, &minus);
  return (plus - minus) / (2 * eps);
}

Matrix CurveSystem::parameter_derivative_of_products(const Vector& u, const Matrix& X,
                                                     int which) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const double value = which == 0 ? p : q;
  const double step = kParameterStep * std::max(1.0, std::abs(value));
  Matrix plus = X, minus = X;
  if (which == 0) {
    maps_.advance(y, p + step, q, period_, &plus);
    maps_.advance(y, p - step, q, period_, &minus);
  } else {
    maps_.advance(y, p, q + step, period_, &plus);
    maps_.advance(y, p, q - step, period_, &minus);
  }
  return (plus - minus) * ((which == 0 ? p_scale_ : q_scale_) / (2 * step));
}

// ---------------------------------------------------------------------------------------------

SingularSystem::SingularSystem(PlaneMaps& maps, int period, Index n, double p_scale,
                               double q_scale, double sigma, const Vector& right,
                               const Vector& left)
    : CurveSystem(maps, period, n, p_scale, q_scale),
      sigma_(sigma),
      b_(left / left.norm()),
      c_(right / right.norm()) {}

bool SingularSystem::evaluate(const Vector& u, Vector& G, Matrix* jacobian) {
  Vector F;
  if (jacobian != nullptr) jacobian->resize(n_ + 1, n_ + 2);
  if (!orbit_rows(u, F, jacobian, true)) return false;
  const Matrix A = M_ - sigma_ * Matrix::Identity(n_, n_);
  if (!solve_bordered(A, b_, c_, last_)) return false;
  G.resize(n_ + 1);
  G.head(n_) = F;
  G(n_) = last_.G(0, 0);
  if (jacobian != nullptr) {
    try {
      const Vector w = last_.W.col(0), v = last_.V.col(0);
      // dg = −v^T (dA) w; along the state by the symmetry of the second derivative of the map,
      // v^T D(M)[e_j] w = v^T D(M)[w] e_j.
      jacobian->row(n_).head(n_) = -(v.transpose() * monodromy_derivative(u, w));
      jacobian->coeffRef(n_, n_) = -v.dot(parameter_derivative_of_products(u, w, 0).col(0));
      jacobian->coeffRef(n_, n_ + 1) = -v.dot(parameter_derivative_of_products(u, w, 1).col(0));
    } catch (const Error&) {
      return false;
    }
    if (!jacobian->allFinite()) return false;
  }
  return std::isfinite(G(n_));
}

void SingularSystem::refresh() {
  if (last_.W.size() == 0) return;
  c_ = last_.W.col(0) / last_.W.col(0).norm();
  b_ = last_.V.col(0) / last_.V.col(0).norm();
}

Vector SingularSystem::right() const { return last_.W.col(0) / last_.W.col(0).norm(); }

Vector SingularSystem::left() const {
  const Vector w = right();
  return last_.V.col(0) / last_.V.col(0).dot(w);
}

std::complex<double> nearest_multiplier(const FloquetMultipliers& mu, double target) {
  std::complex<double> best{kNaN, 0.0};
  for (const auto& m : mu.values) {
    if (std::isnan(best.real()) || std::abs(m - target) < std::abs(best - target)) best = m;
  }
  return best;
}

std::complex<double> SingularSystem::multiplier(const FloquetMultipliers& mu,
                                                const Vector& /*u*/) const {
  return nearest_multiplier(mu, sigma_);
}

// ---------------------------------------------------------------------------------------------

NeimarkSackerSystem::NeimarkSackerSystem(PlaneMaps& maps, int period, Index n, double p_scale,
                                         double q_scale, const Matrix& right, const Matrix& left)
    : CurveSystem(maps, period, n, p_scale, q_scale),
      B_(orthonormal_columns(left)),
      C_(orthonormal_columns(right)) {}

Matrix NeimarkSackerSystem::entry_rows(const Vector& u, const Matrix& M,
                                       const BorderedSolution& s) {
  const double kappa = this->kappa(u);
  const Matrix& W = s.W;
  const Matrix& V = s.V;
  const Matrix MW = M * W;
  const Matrix MtV = M.transpose() * V;
  Matrix D[2], DM[2];  // derivatives of M along W_j and along M W_j
  for (int j = 0; j < 2; ++j) {
    D[j] = monodromy_derivative(u, W.col(j));
    DM[j] = monodromy_derivative(u, MW.col(j));
  }
  Matrix X(n_, 4);
  X << W, MW;
  const Matrix Xp = parameter_derivative_of_products(u, X, 0);
  const Matrix Xq = parameter_derivative_of_products(u, X, 1);
  Matrix rows = Matrix::Zero(4, n_ + 3);
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      const int e = 2 * i + j;
      // dG_ij = −V_i^T (dA) W_j, dA = M dM + dM M − 2κ dM − 2 dκ M.
      rows.row(e).head(n_) = -(MtV.col(i).transpose() * D[j] + V.col(i).transpose() * DM[j] -
                               2 * kappa * V.col(i).transpose() * D[j]);
      rows(e, n_) = -(MtV.col(i).dot(Xp.col(j)) + V.col(i).dot(Xp.col(2 + j)) -
                      2 * kappa * V.col(i).dot(Xp.col(j)));
      rows(e, n_ + 1) = -(MtV.col(i).dot(Xq.col(j)) + V.col(i).dot(Xq.col(2 + j)) -
                          2 * kappa * V.col(i).dot(Xq.col(j)));
      rows(e, n_ + 2) = 2 * V.col(i).dot(MW.col(j));
    }
  }
  return rows;
}

bool NeimarkSackerSystem::evaluate(const Vector& u, Vector& G, Matrix* jacobian) {
  Vector F;
  if (jacobian != nullptr) jacobian->resize(n_ + 2, n_ + 3);
  if (!orbit_rows(u, F, jacobian, true)) return false;
  const double kappa = this->kappa(u);
  const Matrix A = M_ * M_ - 2 * kappa * M_ + Matrix::Identity(n_, n_);
  if (!solve_bordered(A, B_, C_, last_)) return false;
  last_u_ = u;
  G.resize(n_ + 2);
  G.head(n_) = F;
  G(n_) = last_.G(chosen_[0][0], chosen_[0][1]);
  G(n_ + 1) = last_.G(chosen_[1][0], chosen_[1][1]);
  if (jacobian != nullptr) {
    try {
      last_rows_ = entry_rows(u, M_, last_);
    } catch (const Error&) {
      return false;
    }
    jacobian->col(n_ + 2).head(n_).setZero();
    jacobian->row(n_) = last_rows_.row(2 * chosen_[0][0] + chosen_[0][1]);
    jacobian->row(n_ + 1) = last_rows_.row(2 * chosen_[1][0] + chosen_[1][1]);
    // The F rows of the Jacobian, for the choice of the entries at refresh().
    F_rows_ = jacobian->topRows(n_);
    rows_at_ = u;
    if (!jacobian->allFinite()) return false;
  }
  return G.allFinite();
}

void NeimarkSackerSystem::refresh() {
  if (last_.W.size() == 0) return;
  if (rows_at_.size() == last_u_.size() && rows_at_ == last_u_) {
    // The two entries whose gradients, past what the orbit's equations already fix, are the most
    // independent: the pair whose rows projected on the null space of F's rows have the largest
    // smallest singular value.
    const Eigen::HouseholderQR<Matrix> qr(F_rows_.transpose());
    const Matrix Q = qr.householderQ();
    const Matrix null = Q.rightCols(Q.cols() - n_);
    const Matrix projected = last_rows_ * null;
    double best = -1.0;
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) {
        Matrix pair(2, projected.cols());
        pair << projected.row(a), projected.row(b);
        const double smallest =
            Eigen::JacobiSVD<Matrix>(pair).singularValues().minCoeff();
        if (smallest > best) {
          best = smallest;
          chosen_[0][0] = a / 2, chosen_[0][1] = a % 2;
          chosen_[1][0] = b / 2, chosen_[1][1] = b % 2;
        }
      }
    }
  }
  C_ = orthonormal_columns(last_.W);
  B_ = orthonormal_columns(last_.V);
}

std::complex<double> neimark_sacker_multiplier(double kappa) {
  return {kappa, std::sqrt(std::max(0.0, 1 - kappa * kappa))};
}

std::complex<double> NeimarkSackerSystem::multiplier(const FloquetMultipliers& /*mu*/,
                                                     const Vector& u) const {
  return neimark_sacker_multiplier(kappa(u));
}

// ---------------------------------------------------------------------------------------------

GrazingSystem::GrazingSystem(PlaneMaps& maps, int period, Index n, double p_scale,
                             double q_scale, int spring, bool at_largest)
    : CurveSystem(maps, period, n, p_scale, q_scale), spring_(spring), at_largest_(at_largest) {}

bool GrazingSystem::evaluate(const Vector& u, Vector& G, Matrix* jacobian) {
  Vector F;
  if (jacobian != nullptr) jacobian->resize(n_ + 1, n_ + 2);
  if (!orbit_rows(u, F, jacobian, false)) return false;
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  try {
    const GapExtreme e = maps_.gap_extreme(y, p, q, period_, spring_, at_largest_);
    G.resize(n_ + 1);
    G.head(n_) = F;
    G(n_) = e.value;
    if (jacobian != nullptr) {
      // By the envelope theorem (ġ = 0 at the extreme's time t), γ's derivatives are those of
      // g(t) at fixed t: along y the gap function's row of the state transition matrix at t,
      // along p and q the differences of the state at t. A fixed-grid method stops on its grid:
      // the nearest grid time (the row is then an approximation, which only slows Newton).
      const Index dofs = n_ / 2;
      const Vector w = maps_.at(p, q).structure().spring_directions().col(spring_);
      Matrix phi = Matrix::Identity(n_, n_);
      maps_.flow(y, p, q, e.time, &phi);
      jacobian->row(n_).setZero();
      jacobian->row(n_).head(n_) = w.transpose() * phi.topRows(dofs);
      const double dp = kParameterStep * std::max(1.0, std::abs(p));
      const double dq = kParameterStep * std::max(1.0, std::abs(q));
      const auto gap_at = [&](double pp, double qq) {
        const double gap = maps_.at(pp, qq).structure().spring_gaps()(spring_);
        return w.dot(maps_.flow(y, pp, qq, e.time).head(dofs)) - gap;
      };
      jacobian->coeffRef(n_, n_) = (gap_at(p + dp, q) - gap_at(p - dp, q)) * (p_scale_ / (2 * dp));
      jacobian->coeffRef(n_, n_ + 1) =
          (gap_at(p, q + dq) - gap_at(p, q - dq)) * (q_scale_ / (2 * dq));
      if (!jacobian->allFinite()) return false;
    }
  } catch (const Error&) {
    return false;
  }
  return G.allFinite();
}

std::complex<double> GrazingSystem::multiplier(const FloquetMultipliers& /*mu*/,
                                               const Vector& /*u*/) const {
  return {kNaN, kNaN};
}

}  // namespace pwl::orbits::curves_detail
