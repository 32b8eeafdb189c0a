#include "pwl/numerics/precise_exponential.hpp"

#include <cmath>
#include <complex>
#include <string>

#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl {

bool PreciseExponentialOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (doublings < 0 || doublings > 60) {
    *why = fmt::format("doublings = {} must be in 0..60", doublings);
    return false;
  }
  if (taylor_order < 1 || taylor_order > 20) {
    *why = fmt::format("taylor_order = {} must be in 1..20", taylor_order);
    return false;
  }
  return true;
}

int doublings_used(const Matrix& H, double eta, double frequency,
                   const PreciseExponentialOptions& options) {
  if (!options.trim_doublings) return options.doublings;
  const int p = options.taylor_order;
  double factorial = 1.0;  // (p + 1)!
  for (int k = 2; k <= p + 1; ++k) factorial *= k;
  // Beyond θ = 1/2 (orders above 10) the increment is no longer about θ in size and the series
  // itself loses digits to cancellation: the bound stops there.
  const double theta_max = std::min(0.5, std::pow(factorial * std::ldexp(1.0, -53), 1.0 / p));
  // The larger of the 1- and ∞-norms (column and row sums differ when the masses do).
  const double norm = H.size() > 0 ? std::max(H.cwiseAbs().colwise().sum().maxCoeff(),
                                              H.cwiseAbs().rowwise().sum().maxCoeff())
                                   : 0.0;
  const double theta = (norm + std::abs(frequency)) * eta;
  int N = 0;
  while (N < options.doublings && std::ldexp(theta, -N) > theta_max) ++N;
  return N;
}

namespace {

void check_finite(const Matrix& A, const char* name) {
  if (!A.allFinite()) throw InputError(fmt::format("{} has a non-finite entry", name));
}

}  // namespace

PreciseExponential precise_exponential(const Matrix& H, double eta, const Matrix& G,
                                       const Matrix& B, const Vector& omegas,
                                       const PreciseExponentialOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("precise exponential options: " + why);
  if (H.rows() != H.cols()) {
    throw InputError(fmt::format("H is {}x{}: it must be square", H.rows(), H.cols()));
  }
  if (!std::isfinite(eta) || eta <= 0.0) {
    throw InputError(fmt::format("step = {} must be positive and finite", eta));
  }
  const Index n = H.rows();
  if (G.cols() > 0 && G.rows() != n) {
    throw InputError(fmt::format("G has {} rows, H has {}", G.rows(), n));
  }
  if (B.cols() > 0 && B.rows() != n) {
    throw InputError(fmt::format("B has {} rows, H has {}", B.rows(), n));
  }
  if (omegas.size() != B.cols()) {
    throw InputError(fmt::format("{} frequencies for {} load columns", omegas.size(), B.cols()));
  }
  check_finite(H, "H");
  check_finite(G, "G");
  check_finite(B, "B");
  if (!omegas.allFinite()) throw InputError("a load frequency is not finite");

  const Index m = G.cols();
  const Index h = B.cols();
  const int doublings =
      doublings_used(H, eta, h > 0 ? omegas.cwiseAbs().maxCoeff() : 0.0, options);
  double tau = std::ldexp(eta, -doublings);

  // Taylor series at τ. The thin blocks are built from the columns up: H^k G, and for the
  // harmonic columns v_j = Σ_{k+l=j} H^k (iω)^l b, so that Kω(τ) = Σ_j τ^{j+1}/(j+1)! v_j.
  Matrix Ta = Matrix::Zero(n, n);
  Matrix power = Matrix::Identity(n, n);  // (Hτ)^k / k!
  Matrix g0 = Matrix::Zero(n, m), g1 = Matrix::Zero(n, m);
  Matrix HkG = G;  // H^k G
  using Complex = std::complex<double>;
  Eigen::MatrixXcd v = B.cast<Complex>();  // v_0 = b
  Eigen::MatrixXcd kw = Eigen::MatrixXcd::Zero(n, h);
  Eigen::VectorXcd iw_power = Eigen::VectorXcd::Ones(h);  // (iω)^j
  double factorial = 1.0;  // k!
  for (int k = 0; k <= options.taylor_order; ++k) {
    if (k > 0) {
      power = power * H * (tau / k);
      Ta += power;
      factorial *= k;
      HkG = H * HkG;
      for (Index c = 0; c < h; ++c) iw_power[c] *= Complex(0.0, omegas[c]);
      v = H.cast<Complex>() * v;
      for (Index c = 0; c < h; ++c) v.col(c) += iw_power[c] * B.col(c).cast<Complex>();
    }
    // Γ0 term H^k τ^{k+1}/(k+1)!, Γ1 term H^k τ^{k+2}/(k! (k+2)), Kω term τ^{k+1}/(k+1)! v_k.
    const double t1 = std::pow(tau, k + 1) / (factorial * (k + 1));
    g0 += t1 * HkG;
    g1 += (std::pow(tau, k + 2) / (factorial * (k + 2))) * HkG;
    kw += t1 * v;
  }

  // Doublings. All thin blocks use the values at τ before T_a itself is doubled.
  Matrix thin(n, 2 * m + 2 * h);
  for (int d = 0; d < doublings; ++d) {
    thin.leftCols(m) = g0;
    thin.middleCols(m, m) = g1 + tau * g0;
    thin.middleCols(2 * m, h) = kw.real();
    thin.rightCols(h) = kw.imag();
    const Matrix Ta_thin = Ta * thin;
    // Γ1 first: it needs the old Γ0.
    g1 = g1 + thin.middleCols(m, m) + Ta_thin.middleCols(m, m);
    g0 = 2.0 * g0 + Ta_thin.leftCols(m);
    for (Index c = 0; c < h; ++c) {
      const Complex phase = std::exp(Complex(0.0, omegas[c] * tau));
      kw.col(c) = (1.0 + phase) * kw.col(c) +
                  Ta_thin.col(2 * m + c).cast<Complex>() +
                  Complex(0.0, 1.0) * Ta_thin.col(2 * m + h + c).cast<Complex>();
    }
    Ta = 2.0 * Ta + Ta * Ta;
    tau *= 2.0;
  }

  PreciseExponential out;
  out.transition = Ta;
  out.transition.diagonal().array() += 1.0;
  out.gamma0 = std::move(g0);
  out.gamma1 = std::move(g1);
  out.harmonic_real = kw.real();
  out.harmonic_imag = kw.imag();
  return out;
}

Matrix precise_exponential(const Matrix& H, double eta, const PreciseExponentialOptions& options) {
  return precise_exponential(H, eta, Matrix(H.rows(), 0), Matrix(H.rows(), 0), Vector(0), options)
      .transition;
}

}  // namespace pwl
