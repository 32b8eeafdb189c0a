#include "orbits/matrix_free_bordered.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "orbits/bordered_krylov.hpp"
#include "pwl/errors.hpp"

namespace pwl::orbits::curves_detail {

namespace {
// The largest relative perturbation (of the state against its size, of a parameter against its
// value) of the central difference of A W along a direction, as the dense systems differentiate
// the monodromy along a state direction.
constexpr double kDirectionStep = 1e-5;
// GMRES's relative residual for the test functions themselves (they are residuals of the curve's
// equations and must be known below their tolerance) and for their derivatives (the rows'
// products: an error there only slows Newton).
constexpr double kTestTolerance = 1e-12;
constexpr double kRowTolerance = 1e-10;
// A solve that ends more than this factor above the relative residual it was asked for fails.
constexpr double kMissedFactor = 100.0;
}  // namespace

MatrixFreeBordered::MatrixFreeBordered(PlaneMaps& maps, int period, Index n, double p_scale,
                                       double q_scale, CurveType type, const Matrix& right,
                                       double p0, double q0)
    : CurveSystem(maps, period, n, p_scale, q_scale),
      MatrixFreeCurve(maps.options().shooting.tolerance),
      type_(type),
      sigma_(type == CurveType::fold ? 1.0 : type == CurveType::period_doubling ? -1.0 : 0.0),
      border_(orthonormal_columns(right)),
      open_(maps, period, p0, q0, 1.0),
      inner_space_(maps.options().shooting.gmres_recycled, maps.options().shooting.gmres_reform),
      outer_space_(maps.options().shooting.gmres_recycled, maps.options().shooting.gmres_reform) {
  if (type != CurveType::fold) condition_.emplace(maps, period, p0, q0, sigma_);  // NS: set by κ
}

Vector MatrixFreeBordered::entries(const Matrix& G) const {
  if (!neimark_sacker()) return Vector::Constant(1, G(0, 0));
  Vector g(2);
  g << G(chosen_[0][0], chosen_[0][1]), G(chosen_[1][0], chosen_[1][1]);
  return g;
}

bool MatrixFreeBordered::inner(const Vector& u, const Vector& x, const Vector& rho, Vector& w,
                               Vector& s, double tolerance) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const ShootingOptions& shooting = maps_.options().shooting;
  std::function<Vector(const Vector&)> product = monodromy_products(maps_, y, p, q, period_);
  const detail::OpenStructurePreconditioner* open = nullptr;
  double shift = sigma_;
  if (neimark_sacker()) {
    // A v = M(M v) − 2κ M v + v, its own operator (no shift).
    const double k = kappa(u);
    product = [m = std::move(product), k](const Vector& v) -> Vector {
      const Vector mv = m(v);
      return m(mv) - 2 * k * mv + v;
    };
    open = condition_->at(p, q, k);
    shift = 0.0;
  } else {
    open = condition_ ? condition_->at(p, q) : open_.at(p, q);
  }
  const detail::BorderedKrylov system(product, open, border_, border_,
                                      Matrix::Zero(borders(), borders()), 0, shift);
  if (inner_at_.size() != u.size() || inner_at_ != u) {
    inner_space_.operator_changed();
    inner_at_ = u;
  }
  const detail::GmresResult g = system.solve(x, rho, w, s, tolerance, shooting.gmres_dimension,
                                             shooting.gmres_restarts, &inner_space_);
  return g.relative_residual <= kMissedFactor * tolerance && w.allFinite() && s.allFinite();
}

bool MatrixFreeBordered::residuals(const Vector& u, Residuals& r) {
  if (last_at_.size() == u.size() && last_at_ == u) {
    r = last_;
    return true;
  }
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const Index k = borders();
  maps_.pin(p, q);
  try {
    r.F = maps_.advance(y, p, q, period_) - y;  // records the orbit the products replay
    if (!r.F.allFinite()) return false;
    r.W.resize(n_, k);
    r.G.resize(k, k);
    for (Index j = 0; j < k; ++j) {
      Vector w, g;
      if (!inner(u, Vector::Zero(n_), Vector::Unit(k, j), w, g, kTestTolerance)) return false;
      r.W.col(j) = w;
      r.G.col(j) = g;
    }
    if (neimark_sacker()) {
      r.MW = r.W;
      maps_.at(p, q).advance(y, period_, r.MW);
      maps_.result().krylov_products += k;
    }
  } catch (const Error&) {
    return false;
  }
  last_ = r;
  last_at_ = u;
  return true;
}

std::optional<Matrix> MatrixFreeBordered::derivative(const Vector& u, const Residuals& r,
                                                     const Vector& z) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const double dp = z(n_) * p_scale_, dq = z(n_ + 1) * q_scale_;
  const double kappa = this->kappa(u);
  const double relative =
      std::max({z.head(n_).lpNorm<Eigen::Infinity>() / scale(u),
                std::abs(dp) / std::max(1.0, std::abs(p)), std::abs(dq) / std::max(1.0, std::abs(q))});
  if (!std::isfinite(relative)) return std::nullopt;
  const Index k = borders();
  Matrix D = Matrix::Zero(n_, k);  // D(A W)[z]
  try {
    if (relative > 0) {
      const double eps = kDirectionStep / relative;
      // A W from the perturbed states, but for its I W, which the difference cancels.
      const auto AW = [&](double sign) {
        Matrix X = r.W;
        const Vector ys = y + sign * eps * z.head(n_);
        const double ps = p + sign * eps * dp, qs = q + sign * eps * dq;
        maps_.advance(ys, ps, qs, period_, &X);
        if (!neimark_sacker()) return X;
        Matrix Y = X;  // M(M W): a replay of X's integration
        maps_.advance(ys, ps, qs, period_, &Y);
        return Matrix(Y - 2 * kappa * X);
      };
      D = (AW(1.0) - AW(-1.0)) / (2 * eps);
    }
    if (neimark_sacker()) D -= 2 * z(n_ + 2) * r.MW;
  } catch (const Error&) {
    return std::nullopt;
  }
  Matrix dG(k, k);
  for (Index j = 0; j < k; ++j) {
    Vector dw, dg;
    if (!inner(u, -D.col(j), Vector::Zero(k), dw, dg, kRowTolerance)) return std::nullopt;
    dG.col(j) = dg;
  }
  return dG;
}

std::optional<Vector> MatrixFreeBordered::solve(const Vector& u, const Residuals& res,
                                                const Vector& tau, const Vector& r,
                                                const Vector& rho_G, double rho_tau,
                                                double tolerance) {
  const Vector y = u.head(n_);
  const double p = this->p(u), q = this->q(u);
  const ShootingOptions& shooting = maps_.options().shooting;
  const Index m = conditions();
  const Index extra = u.size() - n_;  // p̂, q̂ (and κ): m + 1 of them
  // The stand-in rows: for a fold the null vector's estimate; otherwise an orthonormal basis of
  // the complement of τ's non-state part (the header says why each keeps K regular).
  Matrix E = Matrix::Zero(u.size(), m);
  const Vector t = tau.tail(extra);
  if (type_ == CurveType::fold || !(t.norm() > 0)) {
    if (type_ != CurveType::fold) return std::nullopt;
    E.col(0).head(n_) = border_.col(0);
  } else {
    const Matrix column = t;
    const Eigen::HouseholderQR<Matrix> qr(column);
    const Matrix Q = qr.householderQ() * Matrix::Identity(extra, extra);
    E.bottomRows(extra) = Q.rightCols(m);
  }
  std::vector<Vector> solutions;  // a, then c_1 .. c_m
  try {
    Matrix B = Matrix::Zero(n_, extra);
    B.leftCols(2) = parameter_columns(u);
    if (!B.allFinite()) return std::nullopt;
    Matrix C(n_, extra);
    C << E.topRows(n_), tau.head(n_);
    Matrix D(extra, extra);
    D << E.bottomRows(extra).transpose(), t.transpose();
    const detail::BorderedKrylov K(monodromy_products(maps_, y, p, q, period_), open_.at(p, q), B,
                                   C, D);
    outer_space_.operator_changed();
    for (Index i = 0; i <= m; ++i) {
      Vector rho = Vector::Zero(extra);
      if (i == 0) {
        rho(m) = rho_tau;
      } else {
        rho(i - 1) = 1.0;
      }
      Vector x, s;
      const detail::GmresResult g = K.solve(i == 0 ? r : Vector::Zero(n_), rho, x, s, tolerance,
                                            shooting.gmres_dimension, shooting.gmres_restarts,
                                            &outer_space_);
      if (g.relative_residual > kMissedFactor * tolerance) return std::nullopt;
      Vector z(u.size());
      z << x, s;
      if (!z.allFinite()) return std::nullopt;
      solutions.push_back(std::move(z));
    }
  } catch (const Error&) {
    return std::nullopt;
  }
  // The true rows by their products with a and the c_i (Sherman–Morrison–Woodbury).
  const Vector& a = solutions[0];
  Vector Ra = Vector::Zero(m);
  if (!a.isZero(0.0)) {
    const std::optional<Matrix> dG = derivative(u, res, a);
    if (!dG) return std::nullopt;
    Ra = entries(*dG);
  }
  Matrix Rc(m, m);
  Matrix transverse(borders() * borders(), m);
  for (Index i = 0; i < m; ++i) {
    const std::optional<Matrix> dG = derivative(u, res, solutions[i + 1]);
    if (!dG) return std::nullopt;
    Rc.col(i) = entries(*dG);
    transverse.col(i) = Eigen::Map<const Vector>(dG->data(), dG->size());
  }
  const Eigen::FullPivLU<Matrix> lu(Rc);
  if (!lu.isInvertible()) return std::nullopt;
  const Vector beta = lu.solve(rho_G - Ra);
  Vector delta = a;
  for (Index i = 0; i < m; ++i) delta += beta(i) * solutions[i + 1];
  if (!delta.allFinite()) return std::nullopt;
  transverse_ = std::move(transverse);
  return delta;
}

std::optional<double> MatrixFreeBordered::residual_norm(const Vector& u) {
  Residuals r;
  if (!residuals(u, r)) return std::nullopt;
  return std::max(r.F.lpNorm<Eigen::Infinity>(), entries(r.G).lpNorm<Eigen::Infinity>());
}

std::optional<Vector> MatrixFreeBordered::bordered_solve(const Vector& u, const Vector& tau,
                                                         std::optional<double> arc,
                                                         double tolerance) {
  Residuals r;
  if (!residuals(u, r)) return std::nullopt;
  if (!arc) {
    return solve(u, r, tau, Vector::Zero(n_), Vector::Zero(conditions()), 1.0, tolerance);
  }
  return solve(u, r, tau, -r.F, -entries(r.G), -*arc, tolerance);
}

FloquetMultipliers MatrixFreeBordered::multipliers(const Vector& u, const Eigen::MatrixXcd* warm,
                                                   Eigen::MatrixXcd* ritz) {
  return leading_multipliers(maps_, u.head(n_), p(u), q(u), period_, open_.at(p(u), q(u)), warm,
                             ritz, kOnCircle);
}

bool MatrixFreeBordered::evaluate(const Vector& u, Vector& G, Matrix* jacobian) {
  if (jacobian != nullptr) return false;
  Residuals r;
  if (!residuals(u, r)) return false;
  G.resize(n_ + conditions());
  G << r.F, entries(r.G);
  return true;
}

void MatrixFreeBordered::refresh() {
  if (last_.W.rows() != n_ || !last_.W.allFinite()) return;
  if (neimark_sacker() && transverse_.rows() == 4 && transverse_.cols() == 2 &&
      transverse_.allFinite()) {
    // The two entries whose products along the directions transverse to the curve are the most
    // independent (the largest smallest singular value).
    double best = -1.0;
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) {
        Matrix pair(2, 2);
        pair << transverse_.row(a), transverse_.row(b);
        const double smallest = Eigen::JacobiSVD<Matrix>(pair).singularValues().minCoeff();
        if (smallest > best) {
          best = smallest;
          // dG's entries in column-major order: entry a is G(a % 2, a / 2).
          chosen_[0][0] = a % 2, chosen_[0][1] = a / 2;
          chosen_[1][0] = b % 2, chosen_[1][1] = b / 2;
        }
      }
    }
  }
  border_ = orthonormal_columns(last_.W);
  last_at_.resize(0);  // G depends on the borders
  inner_at_.resize(0);  // and so does the inner operator
  transverse_.resize(0, 0);  // the next choice from the next point's products
}

std::complex<double> MatrixFreeBordered::multiplier(const FloquetMultipliers& mu,
                                                    const Vector& u) const {
  if (neimark_sacker()) return neimark_sacker_multiplier(kappa(u));
  return nearest_multiplier(mu, sigma_);
}

}  // namespace pwl::orbits::curves_detail
