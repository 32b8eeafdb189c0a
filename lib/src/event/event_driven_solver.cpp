// The exact event-driven solver (event_driven_solver.hpp): closed-form motion inside each mode,
// safeguarded event location between modes.
#include "pwl/integrators/event_driven_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <map>
#include <unordered_map>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <fmt/format.h>

#include "event/event_location.hpp"
#include "pwl/errors.hpp"
#include "pwl/numerics/state_checks.hpp"

namespace pwl {

bool EventDrivenOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (representation != "auto" && representation != "modal" && representation != "exponential") {
    *why = fmt::format("representation = \"{}\" must be \"auto\", \"modal\" or \"exponential\"",
                       representation);
    return false;
  }
  if (!(max_eigenvector_condition >= 1.0) || !std::isfinite(max_eigenvector_condition)) {
    *why = fmt::format("max_eigenvector_condition = {} must be finite and >= 1",
                       max_eigenvector_condition);
    return false;
  }
  if (!(resonance_tolerance >= 0.0) || !(resonance_tolerance < 1.0)) {
    *why = fmt::format("resonance_tolerance = {} must be in [0, 1)", resonance_tolerance);
    return false;
  }
  if (!(min_relative_width > 0.0) || !(min_relative_width < 1e-3)) {
    *why = fmt::format("min_relative_width = {} must be in (0, 1e-3)", min_relative_width);
    return false;
  }
  if (!(divergence_bound > 0.0)) {
    *why = fmt::format("divergence_bound = {} must be positive", divergence_bound);
    return false;
  }
  if (max_events < 1) {
    *why = fmt::format("max_events = {} must be at least 1", max_events);
    return false;
  }
  if (max_gap_samples < 1) {
    *why = fmt::format("max_gap_samples = {} must be at least 1", max_gap_samples);
    return false;
  }
  if (!(progress_interval >= 0.0) || !std::isfinite(progress_interval)) {
    *why = fmt::format("progress_interval = {} must be finite and >= 0 (seconds)",
                       progress_interval);
    return false;
  }
  return exponential.is_valid(why);
}

namespace {

using Complex = std::complex<double>;
using ComplexVector = Eigen::VectorXcd;
using ComplexMatrix = Eigen::MatrixXcd;
using event_detail::GapSample;

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
constexpr int kBoundOrders = 8;  // derivative orders with precomputed bounds (exponential form)
constexpr int kSettlePasses = 4;  // mode flips of the springs on their kinks before they rest there

// What every mode shares: the structure in state-space pieces.
struct Structure {
  Index n = 0, m = 0;
  Matrix stiffness_part;  // -M⁻¹K (n x n)
  Matrix damping_part;    // -M⁻¹C (n x n)
  Matrix force_part;      // -M⁻¹W (n x m): velocity rows of the spring-force columns
  Matrix gap_rows;        // W^T (m x n)
  Vector gaps;            // Δ
  Vector stiffnesses;     // k
  Vector gap_scale;       // |Δ_j| + sum_i |W_ij|: to scale rounding tolerances
  Matrix abs_gap_rows;    // |W^T|
  // Load groups in the velocity rows: M⁻¹ times the sin and cos parts, by frequency.
  std::vector<double> omegas;
  std::vector<Vector> sin_parts, cos_parts;
};

// One load frequency of a mode in state space: the forcing Re(β e^{iωt}), β = b_cos - i b_sin.
struct Term {
  double omega;
  ComplexVector beta;  // 2n
};

// The closed-form representation of one mode.
class Mode {
 public:
  virtual ~Mode() = default;
  // Prepare to follow the motion from (t0, v0); s holds the mode signs (+1 touching, -1 slack).
  virtual void start(double t0, const Vector& v0) = 0;
  virtual void sample(const GapSample& from, double t, GapSample& out) = 0;
  virtual void state(const GapSample& at, Vector& v) = 0;
  virtual void derivative_bound(const GapSample& from, double span, int order,
                                Vector& bound) = 0;
  virtual void derivatives(const GapSample& at, int max_order, Matrix& d) = 0;
  virtual double nominal_spacing() const = 0;
  virtual double response_scale() const = 0;  // size of the particular response's x
  virtual bool modal() const = 0;
  // tangent (2n x p) <- exp(H_A delta) tangent: the Jacobian of this mode's flow over delta >= 0.
  virtual void apply_flow_jacobian(double delta, Matrix& tangent) = 0;
};

Matrix mode_state_matrix(const Structure& s, const Vector& kmask) {
  const Index n = s.n;
  Matrix H = Matrix::Zero(2 * n, 2 * n);
  H.topRightCorner(n, n).setIdentity();
  H.bottomLeftCorner(n, n) = s.stiffness_part + s.force_part * kmask.asDiagonal() * s.gap_rows;
  H.bottomRightCorner(n, n) = s.damping_part;
  return H;
}

// A diagonal similarity D = diag(d_x, 1) that balances a state matrix H = [[0, I], [-M⁻¹K_A, -M⁻¹C]]
// (the header's note 1): displacement i is scaled by its degree of freedom's own frequency,
// d_i ≈ √((M⁻¹K_A)_ii), rounded to a power of two so that the scaling is exact (as LAPACK's xGEBAL
// balances before every eigenvalue problem, after Parlett and Reinsch 1969). In the coordinates
// (d_i x_i, x_i') a stiff contact is the skew block [[0, ω], [-ω, 0]]. A degree of freedom
// without stiffness of its own takes the smallest frequency of the others (1 when none has one).
Vector balancing(const Matrix& H, Index n) {
  Vector d = Vector::Ones(2 * n);
  double smallest = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < n; ++i) {
    const double k = -H(n + i, i);
    if (k > 0.0 && std::isfinite(k)) smallest = std::min(smallest, std::sqrt(k));
  }
  if (!std::isfinite(smallest)) return d;
  for (Index i = 0; i < n; ++i) {
    const double k = -H(n + i, i);
    const double w = k > 0.0 && std::isfinite(k) ? std::sqrt(k) : smallest;
    d[i] = std::exp2(std::round(std::log2(w)));
  }
  return d;
}

// The loads of a mode: the structure's groups plus the constant W_A K2_A Δ_A, which joins the
// ω = 0 group.
std::vector<Term> mode_terms(const Structure& s, const Vector& kmask) {
  const Index n = s.n;
  std::vector<Term> terms;
  const Vector preload = -s.force_part * kmask.cwiseProduct(s.gaps);  // M⁻¹ W_A K2_A Δ_A
  bool constant_done = false;
  for (std::size_t g = 0; g < s.omegas.size(); ++g) {
    Term t{s.omegas[g], ComplexVector::Zero(2 * n)};
    t.beta.tail(n) = s.cos_parts[g].cast<Complex>() - Complex(0, 1) * s.sin_parts[g].cast<Complex>();
    if (s.omegas[g] == 0.0) {
      t.beta.tail(n) += preload.cast<Complex>();
      constant_done = true;
    }
    terms.push_back(std::move(t));
  }
  if (!constant_done && preload.cwiseAbs().maxCoeff() > 0.0) {
    Term t{0.0, ComplexVector::Zero(2 * n)};
    t.beta.tail(n) = preload.cast<Complex>();
    terms.push_back(std::move(t));
  }
  return terms;
}

// ---------------------------------------------------------------------------------------------
// Modal representation: H_A = V Λ V⁻¹.
class ModalMode final : public Mode {
 public:
  // Returns nullptr (and says why) when the modal form would be inaccurate.
  static std::unique_ptr<ModalMode> make(const Structure& s, const Vector& kmask,
                                         const Vector& signs, const EventDrivenOptions& o,
                                         std::string* why, double* condition) {
    auto mode = std::unique_ptr<ModalMode>(new ModalMode(s, signs));
    const Matrix H = mode_state_matrix(s, kmask);
    // The eigenvectors V_b of the balanced D H D⁻¹, mapped back: H = (D⁻¹ V_b) Λ (V_b⁻¹ D).
    const Vector d = balancing(H, s.n);
    Eigen::EigenSolver<Matrix> eig(d.asDiagonal() * H * d.cwiseInverse().asDiagonal(), true);
    if (eig.info() != Eigen::Success) {
      *why = "the eigenvalue iteration did not converge";
      return nullptr;
    }
    mode->lambda_ = eig.eigenvalues();
    const ComplexMatrix Vb = eig.eigenvectors();
    Eigen::PartialPivLU<ComplexMatrix> lu(Vb);
    // cond(V_b) in the 1-norm, from the LU factors' estimate of the reciprocal condition number.
    const double rcond = lu.rcond();
    *condition = rcond > 0.0 ? 1.0 / rcond : std::numeric_limits<double>::infinity();
    if (!(*condition <= o.max_eigenvector_condition)) {
      *why = fmt::format("cond(V) = {:.3g} exceeds max_eigenvector_condition = {:.3g} (a "
                         "defective or nearly defective mode)",
                         *condition, o.max_eigenvector_condition);
      return nullptr;
    }
    mode->vinv_ = lu.inverse() * d.cast<Complex>().asDiagonal();
    const ComplexMatrix V = d.cwiseInverse().cast<Complex>().asDiagonal() * Vb;
    mode->v_ = V;
    const Index n = s.n;
    mode->gap_v_ = s.gap_rows.cast<Complex>() * V.topRows(n);
    mode->abs_gap_v_ = mode->gap_v_.cwiseAbs();
    double spectral = 0.0;
    for (Index k = 0; k < mode->lambda_.size(); ++k) spectral = std::max(spectral, std::abs(mode->lambda_[k]));
    for (const Term& t : mode_terms(s, kmask)) spectral = std::max(spectral, t.omega);
    spectral = std::max(spectral, 1e-300);
    for (const Term& t : mode_terms(s, kmask)) {
      const ComplexVector bt = mode->vinv_ * t.beta;
      const double size = bt.cwiseAbs().maxCoeff();
      ModalTerm mt{t.omega, ComplexVector(bt.size()), ComplexVector(), ComplexVector(), Vector()};
      for (Index k = 0; k < bt.size(); ++k) {
        const Complex gap = Complex(0.0, t.omega) - mode->lambda_[k];
        if (std::abs(gap) <= o.resonance_tolerance * spectral &&
            std::abs(bt[k]) > 1e-14 * size) {
          *why = fmt::format("the load at ω = {} is resonant with the mode λ = {}{:+}i", t.omega,
                             mode->lambda_[k].real(), mode->lambda_[k].imag());
          return nullptr;
        }
        // A component forced at rounding level only, exactly at resonance, is left unforced.
        mt.modal[k] = std::abs(bt[k]) > 1e-14 * size && std::abs(gap) > 0.0 ? bt[k] / gap
                                                                           : Complex(0.0);
      }
      mt.state = V * mt.modal;
      mt.gap = mode->gap_v_ * mt.modal;
      mt.abs_gap = mt.gap.cwiseAbs();
      mode->response_scale_ += mt.state.head(n).cwiseAbs().maxCoeff();
      mode->terms_.push_back(std::move(mt));
    }
    mode->spacing_ = 0.25 * M_PI / spectral;
    mode->extend_powers(8);
    for (Index k = 0; k < mode->lambda_.size(); ++k) {
      mode->unstable_ = mode->unstable_ || mode->lambda_[k].real() > 0.0;
    }
    return mode;
  }

  void start(double t0, const Vector& v0) override {
    t0_ = t0;
    // The homogeneous part starts from the real state less the real particular response, so c
    // is conjugate-symmetric like the modes. (Less the complex response, c would also carry a
    // part that moves only the discarded imaginary part, as large as that response's imaginary
    // part in modal coordinates: 1e-5 against a real vibration of 1e-9 on a contact at α = 1e9,
    // and every derivative bound, so every sample spacing, would pay for it.)
    homogeneous_ = v0;
    for (const ModalTerm& t : terms_) {
      homogeneous_ -= (t.state * std::polar(1.0, t.omega * t0)).real();
    }
    c_ = vinv_ * homogeneous_.cast<Complex>();
  }

  void sample(const GapSample&, double t, GapSample& out) override {
    out.t = t;
    z_ = c_.cwiseProduct((lambda_ * (t - t0_)).array().exp().matrix());
    lz_ = lambda_.cwiseProduct(z_);
    llz_ = lambda_.cwiseProduct(lz_);
    g_.noalias() = (gap_v_ * z_).real();
    r_.noalias() = (gap_v_ * lz_).real();
    a_.noalias() = (gap_v_ * llz_).real();
    for (const ModalTerm& term : terms_) {
      const Complex phase = std::polar(1.0, term.omega * t);
      const Complex iw(0.0, term.omega);
      g_ += (term.gap * phase).real();
      r_ += (term.gap * (iw * phase)).real();
      a_ += (term.gap * (iw * iw * phase)).real();
    }
    out.e = signs_.cwiseProduct(g_ - s_.gaps);
    out.rate = signs_.cwiseProduct(r_);
    out.accel = signs_.cwiseProduct(a_);
    // |c_k e^{λ_k τ}|: the size of each modal term now (no overflow guard needed at these sizes).
    out.carry = (z_.real().array().square() + z_.imag().array().square()).sqrt().matrix();
  }

  void state(const GapSample& at, Vector& v) override {
    z_ = c_.cwiseProduct((lambda_ * (at.t - t0_)).array().exp().matrix());
    v = (v_ * z_).real();
    for (const ModalTerm& term : terms_) v += (term.state * std::polar(1.0, term.omega * at.t)).real();
  }

  void derivative_bound(const GapSample& from, double span, int order, Vector& bound) override {
    // Each modal term c_k e^{λ_k τ} λ_k^r has size |z_k| |λ_k|^r at `from`, no more later when
    // Re λ_k <= 0, and at most e^{Re λ_k span} times more otherwise.
    if (order >= static_cast<int>(powers_.cols())) extend_powers(order);
    weights_ = from.carry.cwiseProduct(powers_.col(order));
    if (unstable_) {
      for (Index k = 0; k < lambda_.size(); ++k) {
        const double re = lambda_[k].real();
        if (re > 0.0) weights_[k] *= std::exp(re * span);
      }
    }
    bound.noalias() = abs_gap_v_ * weights_;
    for (const ModalTerm& term : terms_) {
      if (term.omega == 0.0 && order > 0) continue;
      bound += std::pow(term.omega, order) * term.abs_gap;
    }
  }

  void derivatives(const GapSample& at, int max_order, Matrix& d) override {
    d.resize(s_.m, max_order + 1);
    z_ = c_.cwiseProduct((lambda_ * (at.t - t0_)).array().exp().matrix());
    std::vector<Complex> factor;
    for (const ModalTerm& term : terms_) factor.push_back(std::polar(1.0, term.omega * at.t));
    for (int r = 0; r <= max_order; ++r) {
      Vector g = (gap_v_ * z_).real();
      for (std::size_t i = 0; i < terms_.size(); ++i) {
        g += (terms_[i].gap * factor[i]).real();
        factor[i] *= Complex(0.0, terms_[i].omega);  // (iω)^r e^{iωt}
      }
      if (r == 0) g -= s_.gaps;
      d.col(r) = signs_.cwiseProduct(g);
      z_ = lambda_.cwiseProduct(z_);
    }
  }

  double nominal_spacing() const override { return spacing_; }
  double response_scale() const override { return response_scale_; }
  bool modal() const override { return true; }

  // exp(H_A δ) Y = Re(V e^{Λδ} V⁻¹ Y), in real arithmetic on the real and imaginary parts of V
  // and V⁻¹ (split on first use): four 2n x 2n by 2n x p products.
  void apply_flow_jacobian(double delta, Matrix& tangent) override {
    if (!(delta > 0.0) || tangent.cols() == 0) return;
    if (v_re_.size() == 0) {
      v_re_ = v_.real();
      v_im_ = v_.imag();
      vinv_re_ = vinv_.real();
      vinv_im_ = vinv_.imag();
    }
    const ComplexVector e = (lambda_ * delta).array().exp().matrix();
    const Vector e_re = e.real(), e_im = e.imag();
    modal_re_.noalias() = vinv_re_ * tangent;  // V⁻¹ Y
    modal_im_.noalias() = vinv_im_ * tangent;
    scaled_re_ = (modal_re_.array().colwise() * e_re.array() -
                  modal_im_.array().colwise() * e_im.array()).matrix();  // e^{Λδ} V⁻¹ Y
    modal_im_ = (modal_re_.array().colwise() * e_im.array() +
                 modal_im_.array().colwise() * e_re.array()).matrix();
    tangent.noalias() = v_re_ * scaled_re_;  // Re(V ·)
    tangent.noalias() -= v_im_ * modal_im_;
  }

 private:
  struct ModalTerm {
    double omega;
    ComplexVector modal;  // β̃ / (iω - λ): the particular response in modal coordinates
    ComplexVector state;  // V times that
    ComplexVector gap;    // W^T times its displacement rows
    Vector abs_gap;       // |gap|
  };

  // powers_(k, r) = |λ_k|^r
  void extend_powers(int order) {
    const Index old = powers_.cols();
    powers_.conservativeResize(lambda_.size(), order + 1);
    for (Index r = std::max<Index>(old, 0); r <= order; ++r) {
      for (Index k = 0; k < lambda_.size(); ++k) {
        powers_(k, r) = std::pow(std::abs(lambda_[k]), static_cast<double>(r));
      }
    }
  }

  ModalMode(const Structure& s, const Vector& signs) : s_(s), signs_(signs) {}

  const Structure& s_;
  Vector signs_;
  ComplexVector lambda_;
  ComplexMatrix v_, vinv_, gap_v_;
  Matrix abs_gap_v_;
  std::vector<ModalTerm> terms_;
  double spacing_ = 1.0;
  double response_scale_ = 0.0;
  bool unstable_ = false;
  Matrix powers_;
  double t0_ = 0.0;
  ComplexVector c_, z_, lz_, llz_;
  Vector homogeneous_, g_, r_, a_, weights_;
  // The tangent map: the parts of V and V⁻¹ (set on first use) and 2n x p work space.
  Matrix v_re_, v_im_, vinv_re_, vinv_im_;
  Matrix modal_re_, modal_im_, scaled_re_;
};

// ---------------------------------------------------------------------------------------------
// Augmented-exponential representation: w = [v; sin ω_g t, cos ω_g t ...; 1], w' = Ĥ w.
class ExponentialMode final : public Mode {
 public:
  ExponentialMode(const Structure& s, const Vector& kmask, const Vector& signs,
                  const PreciseExponentialOptions& exponential)
      : s_(s), signs_(signs), exponential_(exponential) {
    const Index n = s.n;
    const std::vector<Term> terms = mode_terms(s, kmask);
    for (const Term& t : terms) {
      if (t.omega > 0.0) omegas_.push_back(t.omega);
    }
    const Index q = static_cast<Index>(omegas_.size());
    size_ = 2 * n + 2 * q + 1;
    const Index one = size_ - 1;
    Matrix Hh = Matrix::Zero(size_, size_);
    Hh.topLeftCorner(2 * n, 2 * n) = mode_state_matrix(s, kmask);
    Index g = 0;
    for (const Term& t : terms) {
      if (t.omega == 0.0) {
        Hh.col(one).head(2 * n) += t.beta.real();
        continue;
      }
      const Index si = 2 * n + 2 * g, ci = si + 1;
      Hh.col(si).head(2 * n) = -t.beta.imag();  // sin part: β = b_cos - i b_sin
      Hh.col(ci).head(2 * n) = t.beta.real();
      Hh(si, ci) = t.omega;
      Hh(ci, si) = -t.omega;
      ++g;
    }
    h_ = Hh;
    // Bounds and spacing in balanced coordinates D̂ w: the state balanced as the modal form is
    // (balancing()), each load pair and the constant scaled so that its column is no longer
    // than the state block's norm. Unbalanced, the logarithmic norm of [[0, I], [-ω², 0]] is
    // about ω²/2, and exp(μ u) would force samples 1/ω² apart instead of 1/ω (5e-10 instead of
    // 3e-5 at α = 1e9, for as long as a contact stays closed: the hours of issue 15).
    scale_ = Vector::Ones(size_);
    scale_.head(2 * n) = balancing(Hh.topLeftCorner(2 * n, 2 * n), n);
    const auto balanced = [&] {
      return Matrix(scale_.asDiagonal() * Hh * scale_.cwiseInverse().asDiagonal());
    };
    Matrix Hb = balanced();
    const double norm = Hb.topLeftCorner(2 * n, 2 * n).lpNorm<Eigen::Infinity>();
    for (Index c = 2 * n; c < size_; c += 2) {
      const Index width = std::min<Index>(2, size_ - c);  // a sin/cos pair, or the constant
      const double column = Hb.block(0, c, 2 * n, width).cwiseAbs().colwise().sum().maxCoeff();
      if (norm > 0.0 && column > norm) {
        scale_.segment(c, width).setConstant(std::exp2(std::ceil(std::log2(column / norm))));
      }
    }
    balanced_h_ = balanced();
    // Logarithmic 2-norm: ||D̂ exp(Ĥ u) w|| <= exp(μ u) ||D̂ w||.
    Eigen::SelfAdjointEigenSolver<Matrix> sym(0.5 * (balanced_h_ + balanced_h_.transpose()),
                                              Eigen::EigenvaluesOnly);
    log_norm_ = std::max(0.0, sym.eigenvalues().maxCoeff());
    // Rows whose product with D̂ w is W^T times the displacement rows of Ĥ^r w.
    Matrix rows = Matrix::Zero(s.m, size_);
    rows.leftCols(n) = s.gap_rows * scale_.head(n).cwiseInverse().asDiagonal();
    row_norms_.resize(s.m, kBoundOrders + 1);
    for (int r = 0; r <= kBoundOrders; ++r) {
      row_norms_.col(r) = rows.rowwise().norm();
      rows = rows * balanced_h_;
    }
    balanced_norm_ = balanced_h_.norm();
    double w_max = 0.0;
    for (double w : omegas_) w_max = std::max(w_max, w);
    spacing_ = 0.5 / std::max({norm, w_max, 1e-300});
  }

  void start(double t0, const Vector& v0) override {
    const Index n = s_.n;
    w0_.setZero(size_);
    w0_.head(2 * n) = v0;
    for (std::size_t g = 0; g < omegas_.size(); ++g) {
      w0_[2 * n + 2 * static_cast<Index>(g)] = std::sin(omegas_[g] * t0);
      w0_[2 * n + 2 * static_cast<Index>(g) + 1] = std::cos(omegas_[g] * t0);
    }
    w0_[size_ - 1] = 1.0;
    t0_ = t0;
  }

  void sample(const GapSample& from, double t, GapSample& out) override {
    const Vector& w = from.carry.size() == size_ ? from.carry : w0_;
    const double t_from = from.carry.size() == size_ ? from.t : t0_;
    const double delta = t - t_from;
    out.t = t;
    out.carry = delta == 0.0 ? w : Vector(exponential(delta) * w);
    const Index n = s_.n;
    out.e = signs_.cwiseProduct(s_.gap_rows * out.carry.head(n) - s_.gaps);
    out.rate = signs_.cwiseProduct(s_.gap_rows * out.carry.segment(n, n));
    out.accel = signs_.cwiseProduct(s_.gap_rows * (h_.middleRows(n, n) * out.carry));
  }

  void state(const GapSample& at, Vector& v) override { v = at.carry.head(2 * s_.n); }

  void derivative_bound(const GapSample& from, double span, int order, Vector& bound) override {
    const Vector& w = from.carry.size() == size_ ? from.carry : w0_;
    const double growth = std::exp(log_norm_ * span) * w.cwiseProduct(scale_).norm();
    if (order <= kBoundOrders) {
      bound = row_norms_.col(order) * growth;
    } else {
      // ||Ĥ_b^r|| <= ||Ĥ_b||^(r - kBoundOrders) times the stored rows (balanced).
      bound = row_norms_.col(kBoundOrders) * growth *
              std::pow(balanced_norm_, order - kBoundOrders);
    }
  }

  void derivatives(const GapSample& at, int max_order, Matrix& d) override {
    d.resize(s_.m, max_order + 1);
    Vector u = at.carry;
    for (int r = 0; r <= max_order; ++r) {
      Vector g = s_.gap_rows * u.head(s_.n);
      if (r == 0) g -= s_.gaps;
      d.col(r) = signs_.cwiseProduct(g);
      u = h_ * u;
    }
  }

  double nominal_spacing() const override { return spacing_; }
  double response_scale() const override { return 0.0; }
  bool modal() const override { return false; }

  // exp(H_A δ), the top-left 2n x 2n block of exp(Ĥ_A δ) (Ĥ_A is block upper triangular), by the
  // 2^N algorithm on H_A alone; not cached (segment lengths do not repeat).
  void apply_flow_jacobian(double delta, Matrix& tangent) override {
    if (!(delta > 0.0) || tangent.cols() == 0) return;
    const Index n2 = 2 * s_.n;
    if (state_matrix_.size() == 0) state_matrix_ = balanced_h_.topLeftCorner(n2, n2);
    // exp(H δ) Y = D⁻¹ exp(D H D⁻¹ δ) D Y, D the state's part of D̂.
    const Matrix E = precise_exponential(state_matrix_, delta, exponential_);
    product_.noalias() = E * (scale_.head(n2).asDiagonal() * tangent);
    tangent = scale_.head(n2).cwiseInverse().asDiagonal() * product_;
  }
  const Vector& start_state() const { return w0_; }
  double start_time() const { return t0_; }

 private:
  const Matrix& exponential(double delta) {
    auto it = cache_.find(delta);
    if (it != cache_.end()) return it->second;
    if (cache_.size() > 256) cache_.clear();
    // exp(Ĥδ) = D̂⁻¹ exp(D̂ Ĥ D̂⁻¹ δ) D̂: the 2^N algorithm on the balanced matrix, whose rounding
    // is relative to each component's own scale.
    Matrix E;
    if (delta > 0.0) {
      E = precise_exponential(balanced_h_, delta, exponential_);
    } else {
      // Backwards (only ever by rounding amounts): exp(Ĥδ) = exp((-Ĥ)|δ|).
      E = precise_exponential(Matrix(-balanced_h_), -delta, exponential_);
    }
    E = scale_.cwiseInverse().asDiagonal() * E * scale_.asDiagonal();
    return cache_.emplace(delta, std::move(E)).first->second;
  }

  const Structure& s_;
  Vector signs_;
  PreciseExponentialOptions exponential_;
  std::vector<double> omegas_;
  Index size_ = 0;
  Matrix h_;
  Vector scale_;        // D̂
  Matrix balanced_h_;   // D̂ Ĥ D̂⁻¹
  double balanced_norm_ = 0.0;
  double log_norm_ = 0.0;
  Matrix row_norms_;
  double spacing_ = 1.0;
  Vector w0_;
  double t0_ = 0.0;
  std::map<double, Matrix> cache_;
  Matrix state_matrix_, product_;  // the tangent map: H_A (set on first use), work space
};

// The current mode's gap functions for the event search.
class CurrentGaps final : public event_detail::ModeGaps {
 public:
  Mode* mode = nullptr;
  Index m = 0;
  Index springs() const override { return m; }
  void sample(const GapSample& from, double t, GapSample& out) override {
    mode->sample(from, t, out);
  }
  void derivative_bound(const GapSample& from, double span, int order, Vector& bound) override {
    mode->derivative_bound(from, span, order, bound);
  }
  void derivatives(const GapSample& at, int max_order, Matrix& d) override {
    mode->derivatives(at, max_order, d);
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
struct EventDrivenSolver::Impl {
  EventDrivenOptions options;
  Structure s;
  std::unordered_map<std::uint64_t, std::unique_ptr<Mode>> modes;
  EventDrivenDiagnostics diagnostics;
  IntegratorStats stats;
  EventObserver event_observer;

  std::uint64_t mask = 0;
  Vector signs;  // +1 touching, -1 slack
  Mode* mode = nullptr;
  CurrentGaps gaps;
  event_detail::EventLocator locator;
  GapSample now;
  double t = 0.0;
  Vector x, v, state;
  Vector certified_until;
  std::vector<bool> resting;
  double x_scale = 0.0;

  Mode* mode_for(std::uint64_t active) {
    auto it = modes.find(active);
    if (it != modes.end()) return it->second.get();
    Vector kmask(s.m), sg(s.m);
    for (Index j = 0; j < s.m; ++j) {
      const bool on = (active >> j) & 1u;
      kmask[j] = on ? s.stiffnesses[j] : 0.0;
      sg[j] = on ? 1.0 : -1.0;
    }
    std::unique_ptr<Mode> made;
    if (options.representation != "exponential") {
      std::string why;
      double condition = 0.0;
      made = ModalMode::make(s, kmask, sg, options, &why, &condition);
      if (made) {
        ++diagnostics.modal_modes;
        diagnostics.worst_condition = std::max(diagnostics.worst_condition, condition);
      } else if (options.representation == "modal") {
        throw InputError(fmt::format("representation = \"modal\": the mode with active set {:#x} "
                                     "cannot be represented modally: {}",
                                     active, why));
      }
    }
    if (!made) {
      made = std::make_unique<ExponentialMode>(s, kmask, sg, options.exponential);
      ++diagnostics.exponential_modes;
    }
    return modes.emplace(active, std::move(made)).first->second.get();
  }

  // Rounding tolerances on the mode-signed gaps. Zero (a crossing is a sign change) except for
  // springs found resting on their kink (no significant derivative), which would otherwise
  // raise events at every rounding-level sign flip.
  Vector tolerances() const {
    Vector tol = Vector::Zero(s.m);
    for (Index j = 0; j < s.m; ++j) {
      if (!resting[static_cast<std::size_t>(j)]) continue;
      tol[j] = 256.0 * kEpsilon * (std::abs(s.gaps[j]) + s.abs_gap_rows.row(j).dot(x.cwiseAbs()) +
                                   s.gap_scale[j] * x_scale);
    }
    return tol;
  }

  // Enters the mode of `mask` at time t with state `state`.
  void enter(double time) {
    mode = mode_for(mask);
    for (Index j = 0; j < s.m; ++j) signs[j] = ((mask >> j) & 1u) ? 1.0 : -1.0;
    mode->start(time, state);
    gaps.mode = mode;
    now = GapSample();
    now.t = time;
    mode->sample(now, time, now);
    // The gaps and rates at the start are known exactly from the state; the mode's
    // reconstruction differs by rounding, and a spring at rest on its kink would read
    // e = ±1e-16 and be taken for clearly open or clearly closed.
    now.e = signs.cwiseProduct(s.gap_rows * x - s.gaps);
    now.rate = signs.cwiseProduct(s.gap_rows * v);
    x_scale = std::max({x_scale, x.cwiseAbs().maxCoeff(), mode->response_scale()});
  }

  void set_bit(Index j, bool on) {
    if (on) {
      mask |= (std::uint64_t{1} << j);
    } else {
      mask &= ~(std::uint64_t{1} << j);
    }
  }

  // Springs on (or within rounding of) their kink at the current time get the mode their
  // leading derivatives point to, and a certified departure time. A spring whose first
  // significant derivative points back (it only touched its kink) is flipped back and certified
  // again in the mode it came from. When both modes send it to the other (a derivative
  // significant in one and below the threshold in the other, near a lift-off), the lower order
  // decides: the first derivatives of a gap at its kink are the same in both modes. A spring
  // still undecided after kSettlePasses flips rests on its kink (a rounding tolerance) for
  // min_width.
  void settle(const std::vector<Index>& springs) {
    for (Index j : springs) resting[static_cast<std::size_t>(j)] = false;
    // Per spring: the order that made it leave the first mode it was given (0: not flipped),
    // and the order the two modes' verdicts settled on (0: none).
    std::vector<int> left(springs.size(), 0), assumed(springs.size(), 0);
    for (int pass = 0;; ++pass) {
      const Vector tol = tolerances();
      bool flipped = false;
      for (std::size_t i = 0; i < springs.size(); ++i) {
        const Index j = springs[i];
        double until = t;
        int order = 0;
        const auto certify = [&] {
          return locator.certify_departure(gaps, now, j, tol[j], mode->nominal_spacing(),
                                           min_width(t), &until, assumed[i], &order);
        };
        int verdict = certify();
        if (verdict < 0 && left[i] > 0 && assumed[i] == 0) {
          if (order < left[i]) {
            assumed[i] = order;  // back to the first mode, certified there by this order
          } else if (left[i] < order) {
            assumed[i] = left[i];  // this mode, certified by the first mode's order
            verdict = certify();
          } else {
            verdict = 0;  // the same order both ways: rounding; it rests on its kink
            until = t + min_width(t);
          }
        }
        if (verdict < 0 && pass < kSettlePasses) {
          if (left[i] == 0) left[i] = std::max(order, 1);
          set_bit(j, !((mask >> j) & 1u));
          flipped = true;
        } else {
          certified_until[j] = verdict > 0 ? until : t + min_width(t);
          resting[static_cast<std::size_t>(j)] = verdict <= 0;
        }
      }
      if (!flipped) return;
      enter(t);
    }
  }

  double min_width(double time) const {
    return options.min_relative_width * std::max(std::abs(time), 1.0);
  }

  void sync_state() {
    x = state.head(s.n);
    v = state.tail(s.n);
  }

  // advance_to, with the tangent map applied to *tangent when it is not null.
  void advance(double t_end, Matrix* tangent, const StepObserver& observer);

  void check(double time) const {
    const double largest = state.cwiseAbs().maxCoeff();
    if (!(largest <= options.divergence_bound)) {
      throw_divergence(time, largest, options.divergence_bound);
    }
  }
};

EventDrivenSolver::EventDrivenSolver(const GapStructure& structure,
                                     const EventDrivenOptions& options)
    : impl_(std::make_unique<Impl>()) {
  structure.validate();
  std::string why;
  if (!options.is_valid(&why)) throw InputError("event-driven solver options: " + why);
  if (structure.spring_count() > 62) {
    throw InputError(fmt::format("springs = {}: the event-driven solver handles at most 62 gap "
                                 "springs (its modes are keyed by a 64-bit active set)",
                                 structure.spring_count()));
  }
  Impl& p = *impl_;
  p.options = options;
  Structure& s = p.s;
  s.n = structure.dofs();
  s.m = structure.spring_count();
  const Eigen::LLT<Matrix> mass{Matrix(structure.mass)};
  s.stiffness_part = -mass.solve(Matrix(structure.stiffness));
  s.damping_part = -mass.solve(Matrix(structure.damping));
  const Matrix W = structure.spring_directions();
  s.force_part = s.m > 0 ? Matrix(-mass.solve(W)) : Matrix(s.n, 0);
  s.gap_rows = W.transpose();
  s.abs_gap_rows = s.gap_rows.cwiseAbs();
  s.gaps = structure.spring_gaps();
  s.stiffnesses = structure.spring_stiffnesses();
  s.gap_scale.resize(s.m);
  for (Index j = 0; j < s.m; ++j) s.gap_scale[j] = s.abs_gap_rows.row(j).sum();
  for (const LoadGroup& g : structure.load_groups()) {
    s.omegas.push_back(g.omega);
    s.sin_parts.push_back(mass.solve(g.sin_part));
    s.cos_parts.push_back(mass.solve(g.cos_part));
  }
  p.signs = Vector::Constant(s.m, -1.0);
  p.certified_until = Vector::Constant(s.m, -std::numeric_limits<double>::infinity());
  p.resting.assign(static_cast<std::size_t>(s.m), false);
  p.gaps.m = s.m;
  set_state(0.0, Vector::Zero(s.n), Vector::Zero(s.n));
}

EventDrivenSolver::~EventDrivenSolver() = default;

std::string EventDrivenSolver::name() const {
  const auto& o = impl_->options;
  return fmt::format("exact event-driven ({})", o.representation);
}

Index EventDrivenSolver::dofs() const { return impl_->s.n; }

void EventDrivenSolver::set_state(double t, const Vector& x, const Vector& v) {
  Impl& p = *impl_;
  const Index n = p.s.n;
  check_initial_state(t, x, v, n);
  p.t = t;
  p.state.resize(2 * n);
  p.state << x, v;
  p.sync_state();
  p.x_scale = 0.0;
  p.certified_until.setConstant(-std::numeric_limits<double>::infinity());
  // Springs clearly open or closed take that mode; those within rounding of their kink start
  // slack and are settled by their derivatives.
  const Vector g = p.s.gap_rows * x - p.s.gaps;
  p.x_scale = x.cwiseAbs().maxCoeff();
  std::fill(p.resting.begin(), p.resting.end(), true);
  const Vector tol = p.tolerances();
  std::fill(p.resting.begin(), p.resting.end(), false);
  p.mask = 0;
  std::vector<Index> on_kink;
  for (Index j = 0; j < p.s.m; ++j) {
    if (g[j] > tol[j]) p.set_bit(j, true);
    if (std::abs(g[j]) <= tol[j]) on_kink.push_back(j);
  }
  p.enter(t);
  p.settle(on_kink);
}

double EventDrivenSolver::time() const { return impl_->t; }
const Vector& EventDrivenSolver::position() const { return impl_->x; }
const Vector& EventDrivenSolver::velocity() const { return impl_->v; }

void EventDrivenSolver::Impl::advance(double t_end, Matrix* tangent,
                                     const StepObserver& observer) {
  Impl& p = *this;
  if (!std::isfinite(t_end) || t_end < p.t) {
    throw InputError(fmt::format("event-driven solver: advance_to(t_end = {}) must be finite and "
                                 "not before the current time {}",
                                 t_end, p.t));
  }
  // This call's work, against its budget, and its progress reports.
  const double t_start = p.t;
  const long events_before = p.diagnostics.events;
  long crossings = 0, samples = 0;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point wall_start = Clock::now();
  const auto interval = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(p.options.progress_interval));
  Clock::time_point next_report = wall_start + interval;
  const auto report = [&](double t_now, long samples_now) {
    const Clock::time_point wall = Clock::now();
    if (wall < next_report) return;
    next_report = wall + interval;
    p.options.progress({t_now, t_start, t_end, p.diagnostics.events - events_before, samples_now,
                        std::chrono::duration<double>(wall - wall_start).count()});
  };
  const auto spent = [&](const std::string& budget, const std::string& advice) {
    std::string touching;
    for (Index j = 0; j < p.s.m; ++j) {
      if ((p.mask >> j) & 1u) touching += fmt::format("{}{}", touching.empty() ? "" : ", ", j + 1);
    }
    return BudgetError(fmt::format(
        "event-driven solver: {} of one advance_to call is spent at t = {:.10g} (the call runs "
        "from t = {:.10g} to t_end = {:.10g}): {} switches located ({} kept), {} gap "
        "evaluations; touching now: {} (springs numbered from 1), sampled at least every {:.3g}. "
        "{}",
        budget, p.t, t_start, t_end, crossings, p.diagnostics.events - events_before, samples,
        touching.empty() ? "none" : touching, p.mode->nominal_spacing(), advice));
  };

  event_detail::SearchSettings settings;
  if (p.options.progress) {
    settings.tick = [&](double t_now, long s) { report(t_now, samples + s); };
  }
  double segment_start = p.t;  // the tangent map: where the current mode's segment began
  while (true) {
    settings.nominal_spacing = p.mode->nominal_spacing();
    settings.min_width = p.min_width(t_end);
    settings.tolerance = p.tolerances();
    settings.certified_until = p.certified_until;
    settings.max_samples = std::max<long>(p.options.max_gap_samples - samples, 1);
    const event_detail::SearchResult& r = p.locator.find_first_crossing(p.gaps, p.now, t_end, settings);
    samples += r.samples;
    p.diagnostics.gap_samples += r.samples;
    p.diagnostics.uncertified += r.uncertified;
    p.mode->state(r.at, p.state);
    p.t = r.at.t;
    p.sync_state();
    p.check(p.t);
    if (tangent != nullptr) {
      p.mode->apply_flow_jacobian(p.t - segment_start, *tangent);
      segment_start = p.t;
    }
    if (r.stopped) {
      // No switch before r.at: the solver rests there, in a consistent state.
      p.now = r.at;
      throw spent(fmt::format("the budget max_gap_samples = {}", p.options.max_gap_samples),
                  "Either the contacts are too stiff for event-driven integration at this "
                  "scale (a closed contact is sampled at its own period) or the call is too "
                  "long for the budget: use a fixed-step method (the switching PIM, "
                  "pim-switching, at a step its guard accepts), raise max_gap_samples, or "
                  "advance in shorter calls.");
    }
    if (!r.found) {
      p.now = r.at;
      p.t = t_end;
      ++p.stats.steps;
      if (observer) observer(p.t, p.x, p.v);
      return;
    }
    ++crossings;
    ++p.diagnostics.crossings;
    for (Index j : r.springs) p.set_bit(j, !((p.mask >> j) & 1u));
    p.enter(p.t);
    // Springs leaving their kink now, and those still inside an earlier departure window (the
    // switch changed the forces they feel), are certified again in the new mode.
    const std::vector<Index> switched = r.springs;  // r is overwritten by the next search
    std::vector<Index> settle = switched;
    for (Index j = 0; j < p.s.m; ++j) {
      if (p.certified_until[j] > p.t && std::find(settle.begin(), settle.end(), j) == settle.end()) {
        settle.push_back(j);
      }
    }
    const std::uint64_t before = p.mask;
    p.settle(settle);
    for (Index j : switched) {
      const bool on = (p.mask >> j) & 1u;
      if (on == (((before >> j) & 1u) != 0)) {
        ++p.diagnostics.events;
        ++p.stats.kink_events;
        if (p.event_observer) p.event_observer(p.t, j, on);
      }
    }
    ++p.stats.steps;
    if (observer) observer(p.t, p.x, p.v);
    if (crossings > p.options.max_events) {
      throw spent(fmt::format("the budget max_events = {}", p.options.max_events),
                  "Either the contacts switch too often for event-driven integration over "
                  "this interval (chattering at a grazing contact, or contacts too stiff at "
                  "this scale) or the call is too long for the budget: use a fixed-step "
                  "method (the switching PIM, pim-switching), raise max_events, or advance in "
                  "shorter calls.");
    }
    if (p.options.progress) report(p.t, samples);
  }
}

void EventDrivenSolver::advance_to(double t_end, const StepObserver& observer) {
  impl_->advance(t_end, nullptr, observer);
}

void EventDrivenSolver::advance_with_tangent(double t_end, Matrix& tangent,
                                             const StepObserver& observer) {
  const Index rows = 2 * impl_->s.n;
  if (tangent.rows() != rows) {
    throw InputError(fmt::format("event-driven solver: the tangent has {} rows, the state {}",
                                 tangent.rows(), rows));
  }
  impl_->advance(t_end, &tangent, observer);
}

IntegratorStats EventDrivenSolver::stats() const { return impl_->stats; }
EventDrivenDiagnostics EventDrivenSolver::diagnostics() const { return impl_->diagnostics; }

bool EventDrivenSolver::touching(Index spring) const {
  if (spring < 0 || spring >= impl_->s.m) {
    throw InputError(fmt::format("touching(spring = {}): springs are numbered 0..{}", spring,
                                 impl_->s.m - 1));
  }
  return (impl_->mask >> spring) & 1u;
}

void EventDrivenSolver::set_event_observer(EventObserver observer) {
  impl_->event_observer = std::move(observer);
}

std::unique_ptr<Integrator> make_event_driven_solver(const GapStructure& structure,
                                                     const EventDrivenOptions& options) {
  return std::make_unique<EventDrivenSolver>(structure, options);
}

}  // namespace pwl
