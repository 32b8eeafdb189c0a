#pragma once
// Fold, period-doubling and Neimark–Sacker curves without the monodromy: the minimally augmented
// defining systems of SingularSystem and NeimarkSackerSystem (the orbit's equations
// F(y; p, q) = φ_kT(y) − y = 0 and entries of a bordered test matrix G), corrected by Newton–Krylov
// for the structures whose monodromy is too large to form.
//
// The test functions. G (k × k) is the lower block of the solution of
//
//     [ A   B ] [ W ]   [ 0  ]
//     [ Bᵀ  0 ] [ G ] = [ I_k ],
//
// with A = M − σI and k = 1 for a fold (σ = +1) or a period doubling (σ = −1), and A = M² − 2κM + I
// with k = 2 and κ = cos ω an unknown for a Neimark–Sacker point (G = 0 where A has a null space
// of the dimension k: a multiplier at σ, or a pair e^{±iω}). Each column is solved by GMRES on
// products of A (bordered_krylov.hpp): products of M, each replayed from the orbit's recorded
// integration where the integrator records, preconditioned by the open structure's counterpart of
// A ((M0 − σI)⁻¹, or (M0² − 2κM0 + I)⁻¹, the same 2 x 2 modal blocks). The dense systems border
// with the left and right null vectors; the left ones need products with Mᵀ, which the tangent map
// does not give. Both borders here are the right ones, orthonormalised (at the start from the
// Arnoldi Ritz vector of the multiplier nearest σ, or the real and imaginary parts of the pair's,
// then W of each accepted point): the bordered matrix is regular where VᵀB is, V the left null
// vectors, and for a simple multiplier (a simple pair) VᵀW is always. A fold or period doubling
// takes g = G as its condition; a Neimark–Sacker point two of the four entries, the pair whose
// products along the directions transverse to the curve are the most independent (chosen at each
// accepted point, as the dense system chooses by its gradients).
//
// Their rows. Differentiating the bordered system, the derivative of G along z = (z_y, ẑ_p, ẑ_q,
// z_κ) has the columns dG_j of the solutions of the same system with right-hand sides
// [−D(A W_j)[z]; 0], where D(A W)[z] is the derivative of A W along z in state and parameters (a
// central difference of tangent integrations of W from the perturbed states: M W, and for the
// Neimark–Sacker form M(M W), the second a replay of the first's integration) and in κ
// (−2 z_κ M W). The bordered test functions and their derivatives: W. Govaerts, Numerical Methods
// for Bifurcations of Dynamical Equilibria, SIAM 2000, ch. 3 and 4. The rows of the conditions are
// so known only by their products, each k inner solves, which a GMRES on the whole bordered system
// would need once per product.
//
// A Newton step or a tangent solves instead
//
//     [ M − I   ∂F/∂p̂   ∂F/∂q̂   0 ]       [ r   ]
//     [ Rᵀ (the conditions' rows)  ] δ  =  [ ρ_G ]
//     [ τᵀ                         ]       [ ρ_τ ]
//
// with the m rows R (m = 1 or 2) taken by their products only: they are replaced by known stand-in
// rows E, with which the system K is bordered like the grazing curve's (bordered_krylov.hpp), and
// K a = [r; 0; ρ_τ], K c_i = [0; e_i; 0] give δ = a + Σ β_i c_i with (Rᵀc) β = ρ_G − Rᵀa (the
// matrix differs from K in m rows: a rank-m correction, Sherman–Morrison–Woodbury). K must be
// regular. For a period doubling or a Neimark–Sacker point M − I is, and K's rows restricted to the
// null space of the orbit's rows (whose coordinates are the non-state unknowns) are E's and
// τ's: E spanning the complement of τ's non-state part (the curve's normal in the parameter plane,
// or with κ the plane normal to the curve in (p̂, q̂, κ)) makes K regular wherever τ is near the
// curve's tangent. At a fold M − I is singular along the null vector, which E = (B, 0, 0) covers.
// Where a curve meets a point at which these arguments fail, K is singular there and ill-conditioned
// near it: a period-doubling curve's fold–flip point and a Neimark–Sacker curve's fold–NS point
// (M − I singular too, along a null vector E does not see), a fold curve's cusp (τ along the null
// vector, as E is). The step's two parts then grow and cancel; the tests pass through a fold–flip
// point (located within 6e-13 of the dense curve's) and a cusp on small systems, but a curve
// through such a point of a long chain may lose accuracy or stop there. A step costs m + 1 bordered
// GMRES solves (each failing where GMRES ends far above its tolerance), the parameter columns'
// four integrations, and m + 1 products of the rows: 2(m + 1) tangent integrations from perturbed
// states, k(m + 1) inner solves.
//
// The leading multipliers come from Arnoldi (matrix_free_curve.hpp), with every multiplier within
// kOnCircle of the unit circle among them: the curve's own (±1 or the pair) is reported even where
// many others lie outside the circle. The fold's cusp and the period doubling's generalised
// coefficient need the left null vector and are not computed here.
#include <optional>

#include "orbits/curve_systems.hpp"
#include "orbits/gmres.hpp"
#include "orbits/matrix_free_curve.hpp"

namespace pwl::orbits::curves_detail {

class MatrixFreeBordered : public CurveSystem, public MatrixFreeCurve {
 public:
  // The band inside the unit circle whose multipliers Arnoldi reports (ArnoldiOptions::margin) on
  // the curve and at its start.
  static constexpr double kOnCircle = 1e-3;

  // `type`: fold, period_doubling or neimark_sacker; `right`: the right null vector's estimate at
  // the start (p0, q0) (n × 1), or the pair's invariant subspace's (n × 2).
  MatrixFreeBordered(PlaneMaps& maps, int period, Index n, double p_scale, double q_scale,
                     CurveType type, const Matrix& right, double p0, double q0);

  // G = (F, the conditions) at u. Without its Jacobian: false where one is asked for (it is never
  // formed).
  bool evaluate(const Vector& u, Vector& G, Matrix* jacobian) override;
  // The borders become the right null vectors of the last point evaluated, and a Neimark–Sacker
  // curve's two entries those of the last step's transverse products.
  void refresh() override;
  std::complex<double> multiplier(const FloquetMultipliers& mu, const Vector& u) const override;

  FloquetMultipliers multipliers(const Vector& u, const Eigen::MatrixXcd* warm,
                                 Eigen::MatrixXcd* ritz) override;

 protected:
  const CurveSystem& curve() const override { return *this; }
  std::optional<double> residual_norm(const Vector& u) override;
  std::optional<Vector> bordered_solve(const Vector& u, const Vector& tau,
                                       std::optional<double> arc, double tolerance) override;

 private:
  // The residuals at u and the inner solution there.
  struct Residuals {
    Vector F;
    Matrix W;   // n × k: A W + B G = 0, Bᵀ W = I
    Matrix G;   // k × k
    Matrix MW;  // M W (the Neimark–Sacker form's derivative in κ)
  };
  bool neimark_sacker() const { return type_ == CurveType::neimark_sacker; }
  Index borders() const { return border_.cols(); }
  Index conditions() const { return neimark_sacker() ? 2 : 1; }
  double kappa(const Vector& u) const { return neimark_sacker() ? u(n_ + 2) : 0.0; }
  // The conditions' values among G's entries.
  Vector entries(const Matrix& G) const;
  bool residuals(const Vector& u, Residuals& r);
  // [A, B; Bᵀ, 0]⁻¹ [x; ρ] at u, whose map has recorded the orbit: (w, s).
  bool inner(const Vector& u, const Vector& x, const Vector& rho, Vector& w, Vector& s,
             double tolerance);
  // dG along z at u.
  std::optional<Matrix> derivative(const Vector& u, const Residuals& r, const Vector& z);
  // Solves [J; τᵀ] δ = [r; ρ_G; ρ_τ] at u.
  std::optional<Vector> solve(const Vector& u, const Residuals& res, const Vector& tau,
                              const Vector& r, const Vector& rho_G, double rho_tau,
                              double tolerance);

  CurveType type_;
  double sigma_ = 0.0;  // fold +1, period doubling −1 (Neimark–Sacker 0: A is its own operator)
  Matrix border_;       // n × k
  int chosen_[2][2] = {{0, 0}, {1, 1}};  // Neimark–Sacker: the two entries of G kept
  CurvePreconditioner open_;  // (M0 − I)⁻¹: the orbit's equations, a fold's condition
  std::optional<CurvePreconditioner> condition_;  // (M0 + I)⁻¹ or (M0² − 2κM0 + I)⁻¹
  Residuals last_;
  Vector last_at_;
  // GMRES's recycled subspaces (gmres.hpp): of the inner system [A, B; Bᵀ, 0], whose k(m + 2)
  // right-hand sides of a Newton step share one operator (at inner_at_), and of K, whose m + 1
  // share another. A new point drops them (gmres.hpp says why).
  detail::RecycledSubspace inner_space_, outer_space_;
  Vector inner_at_;
  // G's entries' products along the c_i of the last step that succeeded (k² × m; Neimark–Sacker:
  // 4 × 2), emptied at each accepted point.
  Matrix transverse_;
};

}  // namespace pwl::orbits::curves_detail
