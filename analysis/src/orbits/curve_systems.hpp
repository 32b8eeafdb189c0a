#pragma once
// The defining systems of the bifurcation curves (bifurcation_curves.hpp says what each poses),
// on the continuation core's interface. The unknowns are u = (y, p̂, q̂, aux): the orbit's state,
// the two parameters scaled by the widths of their ranges (p = p̂ · p_scale), so that a step of
// the curve is measured in the plane the curves are drawn in, and κ = cos ω for a Neimark–Sacker
// curve. The maps of every (p, q) come from one cache, which counts what they integrate.
#include <map>
#include <memory>
#include <optional>
#include <utility>

#include "bordered_singularity.hpp"
#include "pwl/orbits/arclength_continuation.hpp"
#include "pwl/orbits/bifurcation_curves.hpp"
#include "pwl/orbits/orbit_profile.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"

namespace pwl::orbits::curves_detail {

// The stroboscopic maps of the model at (p, q), built once each and counted.
class PlaneMaps {
 public:
  PlaneMaps(const analysis::PointModel& model, const CurvesOptions& options, CurvesResult& result);
  StroboscopicMap& at(double p, double q);
  bool accepts(double p, double q) const;
  // φ(y) over `period` forcing periods, and with `tangent` its product with the Jacobian; a
  // monodromy when the tangent has every column (counted as such).
  Vector advance(const Vector& y, double p, double q, int period, Matrix* tangent = nullptr);
  // The profile of the orbit through y, and one extreme of one gap function along it.
  OrbitProfile profile(const Vector& y, double p, double q, int period);
  GapExtreme gap_extreme(const Vector& y, double p, double q, int period, int spring,
                         bool largest);
  // The state at time t from y at 0 (a fixed-grid method's nearest grid time), and with
  // `tangent` its product with the state transition matrix.
  Vector flow(const Vector& y, double p, double q, double t, Matrix* tangent = nullptr);
  // t, or a fixed-grid method's nearest grid time to it.
  double on_grid(double p, double q, double t);
  // A second map of (p, q): where products alternate between two arcs of one orbit (up to a time
  // within the period and on from there), each map records and replays its own arc.
  StroboscopicMap& second_at(double p, double q);
  // Keeps the maps of (p, q) (both caches) when a cache is emptied: a caller that integrates at
  // nearby parameters between the products at (p, q) keeps what the maps of (p, q) recorded.
  void pin(double p, double q) { pinned_ = std::make_pair(p, q); }
  const CurvesOptions& options() const { return options_; }
  CurvesResult& result() { return result_; }

 private:
  analysis::PointModel model_;
  const CurvesOptions& options_;
  CurvesResult& result_;
  std::map<std::pair<double, double>, StroboscopicMap> maps_, seconds_;
  std::optional<std::pair<double, double>> pinned_;
  // The map of (p, q) from `cache`, built there when missing (the cache emptied first, but for
  // the pinned map, when it holds more than `most`).
  StroboscopicMap& cached(std::map<std::pair<double, double>, StroboscopicMap>& cache,
                          std::size_t most, double p, double q);
};

// What every curve's system shares: the layout of u, the orbit's equations and their Jacobian,
// the monodromy at the last point evaluated with it, and the domain.
class CurveSystem : public DefiningSystem {
 public:
  CurveSystem(PlaneMaps& maps, int period, Index n, double p_scale, double q_scale)
      : maps_(maps), period_(period), n_(n), p_scale_(p_scale), q_scale_(q_scale) {}

  Index state_size() const override { return n_; }
  bool admissible(const Vector& u) const override;
  double p(const Vector& u) const { return u(n_) * p_scale_; }
  double q(const Vector& u) const { return u(n_ + 1) * q_scale_; }
  int period() const { return period_; }
  // The unknowns of a point (y, p, q), with aux (κ) where the system has one.
  Vector unknowns(const Vector& y, double p, double q, std::optional<double> aux = {}) const;
  // The monodromy at the last point evaluated with its Jacobian (or its test function needed it).
  const Matrix& monodromy() const { return M_; }
  // After a point is accepted: borders and choices refreshed from it (the last point evaluated).
  virtual void refresh() {}
  // The multiplier the curve's condition puts on the unit circle (NaN for grazing).
  virtual std::complex<double> multiplier(const FloquetMultipliers& mu, const Vector& u) const = 0;

 protected:
  // F = φ(y) − y at u; with `jacobian` (m × (n + 2 + aux) already sized) its first n rows
  // [M − I, ∂F/∂p̂, ∂F/∂q̂, 0]; with `monodromy`, M at u. The monodromy of the same u is kept, so
  // that a second evaluation at the point does not integrate again.
  bool orbit_rows(const Vector& u, Vector& F, Matrix* jacobian, bool monodromy);
  // [∂F/∂p̂, ∂F/∂q̂] at u by central differences (n × 2).
  Matrix parameter_columns(const Vector& u);
  // The derivative of the monodromy along the state direction v at u: (M(y + εv) − M(y − εv))/2ε.
  Matrix monodromy_derivative(const Vector& u, const Vector& v);
  // The derivatives along p̂ and q̂ of M·X (X: n × c) at fixed y.
  Matrix parameter_derivative_of_products(const Vector& u, const Matrix& X, int which);

  PlaneMaps& maps_;
  int period_;
  Index n_;
  double p_scale_, q_scale_;
  Matrix M_;
  Vector M_at_;  // the u whose monodromy M_ is
  Vector F_, F_at_;
};

// The multiplier of `mu` nearest `target` (NaN where there is none).
std::complex<double> nearest_multiplier(const FloquetMultipliers& mu, double target);
// The multiplier e^{iω} of a Neimark–Sacker curve's condition, cos ω = κ.
std::complex<double> neimark_sacker_multiplier(double kappa);

// Fold (σ = +1, A = M − I) and period doubling (σ = −1, A = M + I): one bordered condition.
class SingularSystem : public CurveSystem {
 public:
  SingularSystem(PlaneMaps& maps, int period, Index n, double p_scale, double q_scale,
                 double sigma, const Vector& right, const Vector& left);
  bool evaluate(const Vector& u, Vector& G, Matrix* jacobian) override;
  void refresh() override;
  std::complex<double> multiplier(const FloquetMultipliers& mu, const Vector& u) const override;
  // The null vectors at the last point evaluated (right w, left v), normalised |w| = 1,
  // v^T w = 1.
  Vector right() const;
  Vector left() const;
  double sigma() const { return sigma_; }

 private:
  double sigma_;
  Vector b_, c_;  // borders
  BorderedSolution last_;
};

// Neimark–Sacker: M² − 2κM + I singular with κ an unknown; two entries of the doubly bordered G.
class NeimarkSackerSystem : public CurveSystem {
 public:
  NeimarkSackerSystem(PlaneMaps& maps, int period, Index n, double p_scale, double q_scale,
                      const Matrix& right, const Matrix& left);
  bool evaluate(const Vector& u, Vector& G, Matrix* jacobian) override;
  void refresh() override;
  std::complex<double> multiplier(const FloquetMultipliers& mu, const Vector& u) const override;
  double kappa(const Vector& u) const { return u(n_ + 2); }

 private:
  // The gradient rows (w.r.t. u) of the four entries of G at u; the borders as they are.
  Matrix entry_rows(const Vector& u, const Matrix& M, const BorderedSolution& s);
  Matrix B_, C_;  // borders (n × 2)
  int chosen_[2][2] = {{0, 0}, {1, 1}};  // the two entries of G kept: (row, column) each
  BorderedSolution last_;
  Vector last_u_;
  Matrix last_rows_;  // the four entries' gradients at rows_at_
  Matrix F_rows_;     // the orbit's equations' rows of the Jacobian at rows_at_
  Vector rows_at_;
};

// Grazing of one spring: the largest (or smallest) value of its gap function along the orbit is
// zero.
class GrazingSystem : public CurveSystem {
 public:
  GrazingSystem(PlaneMaps& maps, int period, Index n, double p_scale, double q_scale, int spring,
                bool at_largest);
  bool evaluate(const Vector& u, Vector& G, Matrix* jacobian) override;
  std::complex<double> multiplier(const FloquetMultipliers& mu, const Vector& u) const override;

 protected:
  int spring_;
  bool at_largest_;
};

}  // namespace pwl::orbits::curves_detail
