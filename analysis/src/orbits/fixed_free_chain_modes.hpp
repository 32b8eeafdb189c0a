#pragma once
// The modes of a uniform fixed-free chain in closed form, and the transforms to and from them in
// O(n log n) by the fast Fourier transform, so that the open structure's preconditioner of a chain
// of 10^4 or 10^5 masses needs neither the O(n³) eigen-decomposition nor the n x n modal matrix
// (800 MB at 10^4 masses).
//
// The chain: n equal masses m, each tied to the next by a spring k (the first to a wall, the last
// free), so that M = m I and K = k L with L = tridiag(−1, 2, −1), L[n−1][n−1] = 1. With
// N' = 2n + 1 and θ_k = (2k − 1) π / N' (k = 1 .. n), the mass-normalised modes and their
// frequencies are
//     φ_k(j) = c sin(j θ_k) / √m,  c = 2 / √N',   ω_k² = (k/m) · 4 sin²(θ_k / 2),   j = 1 .. n
// (2 sin jθ − sin (j−1)θ − sin (j+1)θ = 4 sin²(θ/2) sin jθ, the wall gives sin 0θ = 0, and the
// free end sin (n+1)θ_k = sin nθ_k because (2n+1) θ_k is an odd multiple of π;
// Σ_j sin² jθ_k = N'/4). Both transforms are products with the n x n sine matrix
// S_jk = sin(j θ_k) or its transpose, and both are the imaginary part of one discrete Fourier
// transform of length L = 2N' (e^{−2πi m j / L} = e^{−i π m j / N'}):
//     (S z)_j  = −Im DFT(a)_j,      a_{2k−1} = z_k, other entries 0;
//     (Sᵀ y)_k = −Im DFT(b)_{2k−1}, b_j = y_j, other entries 0.
// Two real inputs share one complex transform (F = DFT(a + i b): DFT(a)_j = (F_j + conj F_{L−j})/2,
// DFT(b)_j = (F_j − conj F_{L−j}) / 2i), which is how the two halves of a state vector go through.
//
// The DFT of length L: Eigen's FFT (its kissfft back end) when L has no prime factor above 16;
// otherwise Bluestein's chirp-z form, a circular convolution of power-of-two length, so that no
// chain length falls on a slow prime-length transform (L. I. Bluestein, IEEE Trans. Audio
// Electroacoust. 18 (1970) 451-455; W. H. Press et al., Numerical Recipes, 3rd ed., §12.3-12.4 for
// sine transforms by the FFT).
#include <unsupported/Eigen/FFT>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::orbits::detail {

class FixedFreeChainModes {
 public:
  using Complex = std::complex<double>;

  // Modes of the chain with masses m and springs k (both > 0), n >= 1 masses.
  FixedFreeChainModes(Index n, double mass, double spring)
      : n_(n), length_(2 * (2 * n + 1)), mass_(mass) {
    const double odd = double(2 * n + 1);
    scale_ = 2.0 / std::sqrt(odd);
    laplacian_eigenvalues_.resize(n);
    omega2_.resize(n);
    for (Index k = 0; k < n; ++k) {
      const double half = 0.5 * double(2 * k + 1) * std::numbers::pi / odd;
      laplacian_eigenvalues_(k) = 4.0 * std::sin(half) * std::sin(half);
      omega2_(k) = spring / mass * laplacian_eigenvalues_(k);
    }
    if (largest_prime_factor(length_) > 16) prepare_bluestein();
  }

  Index size() const { return n_; }
  // ω_k² and the eigenvalues λ_k of L (ω_k² = (k/m) λ_k), k = 1 .. n in increasing order.
  const Vector& omega2() const { return omega2_; }
  const Vector& laplacian_eigenvalues() const { return laplacian_eigenvalues_; }

  // Modal coordinates q = Φᵀ M r of two vectors at once.
  void to_modal(const Eigen::Ref<const Vector>& rx, const Eigen::Ref<const Vector>& rv, Vector& qx,
                Vector& qv) const {
    std::vector<Complex> in(static_cast<std::size_t>(length_), Complex(0.0, 0.0));
    for (Index j = 0; j < n_; ++j) in[static_cast<std::size_t>(j + 1)] = Complex(rx(j), rv(j));
    const std::vector<Complex> F = dft(in);
    const double factor = -scale_ * std::sqrt(mass_);
    qx.resize(n_);
    qv.resize(n_);
    for (Index k = 0; k < n_; ++k) {
      const Index m = 2 * k + 1;
      const Complex a = 0.5 * (F[idx(m)] + std::conj(F[idx(length_ - m)]));
      const Complex b = (F[idx(m)] - std::conj(F[idx(length_ - m)])) / Complex(0.0, 2.0);
      qx(k) = factor * a.imag();
      qv(k) = factor * b.imag();
    }
  }

  // Physical vectors x = Φ z of two modal vectors at once.
  void from_modal(const Vector& zx, const Vector& zv, Eigen::Ref<Vector> x,
                  Eigen::Ref<Vector> v) const {
    std::vector<Complex> in(static_cast<std::size_t>(length_), Complex(0.0, 0.0));
    for (Index k = 0; k < n_; ++k) in[idx(2 * k + 1)] = Complex(zx(k), zv(k));
    const std::vector<Complex> F = dft(in);
    const double factor = -scale_ / std::sqrt(mass_);
    for (Index j = 0; j < n_; ++j) {
      const Index m = j + 1;
      const Complex a = 0.5 * (F[idx(m)] + std::conj(F[idx(length_ - m)]));
      const Complex b = (F[idx(m)] - std::conj(F[idx(length_ - m)])) / Complex(0.0, 2.0);
      x(j) = factor * a.imag();
      v(j) = factor * b.imag();
    }
  }

 private:
  static std::size_t idx(Index i) { return static_cast<std::size_t>(i); }

  static Index largest_prime_factor(Index value) {
    Index largest = 1;
    for (Index p = 2; p * p <= value; ++p) {
      while (value % p == 0) {
        largest = p;
        value /= p;
      }
    }
    return std::max(largest, value);
  }

  // X_j = Σ_m x_m e^{−2πi m j / L}.
  std::vector<Complex> dft(const std::vector<Complex>& x) const {
    std::vector<Complex> out;
    if (chirp_.empty()) {
      fft_.fwd(out, x);
      return out;
    }
    // Bluestein: m j = (m² + j² − (j − m)²) / 2, so X_j = w̄_j Σ_m (x_m w̄_m) w_{j−m} with
    // w_m = e^{iπ m² / L}: a convolution, done circularly at the power-of-two length P >= 2L − 1.
    const std::size_t P = chirp_spectrum_.size();
    std::vector<Complex> a(P, Complex(0.0, 0.0)), A;
    for (std::size_t m = 0; m < x.size(); ++m) a[m] = x[m] * std::conj(chirp_[m]);
    fft_.fwd(A, a);
    for (std::size_t i = 0; i < P; ++i) A[i] *= chirp_spectrum_[i];
    std::vector<Complex> convolution;
    fft_.inv(convolution, A);
    out.resize(x.size());
    for (std::size_t j = 0; j < x.size(); ++j) out[j] = std::conj(chirp_[j]) * convolution[j];
    return out;
  }

  void prepare_bluestein() {
    const Index L = length_;
    chirp_.resize(idx(L));
    for (Index m = 0; m < L; ++m) {
      // m² mod 2L keeps the angle small and exact for any chain length.
      const Index reduced = (m * m) % (2 * L);
      chirp_[idx(m)] = std::polar(1.0, std::numbers::pi * double(reduced) / double(L));
    }
    std::size_t P = 1;
    while (P < idx(2 * L - 1)) P *= 2;
    std::vector<Complex> b(P, Complex(0.0, 0.0));
    b[0] = chirp_[0];
    for (Index m = 1; m < L; ++m) b[idx(m)] = b[P - idx(m)] = chirp_[idx(m)];
    fft_.fwd(chirp_spectrum_, b);
  }

  Index n_, length_;
  double mass_, scale_ = 1.0;
  Vector laplacian_eigenvalues_, omega2_;
  std::vector<Complex> chirp_, chirp_spectrum_;
  mutable Eigen::FFT<double> fft_;
};

}  // namespace pwl::orbits::detail
