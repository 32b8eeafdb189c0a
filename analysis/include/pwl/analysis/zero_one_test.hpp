#pragma once
// The 0-1 test for chaos on a scalar observable series.
//
// Gottwald & Melbourne, Proc. R. Soc. Lond. A 460 (2004) 603 (the test); Gottwald & Melbourne,
// SIAM J. Appl. Dyn. Syst. 8 (2009) 129 (the correlation form and its implementation, used here).
//
// The series φ(1..N) drives a walk in the plane,
//
//     p_c(n) = Σ_{j<=n} φ(j) cos(j c),   q_c(n) = Σ_{j<=n} φ(j) sin(j c),
//
// which stays bounded when the motion is regular (periodic or quasi-periodic; c off resonance)
// and behaves like a Brownian motion, growing diffusively, when it is chaotic. The growth is read
// from the mean-square displacement
//
//     M_c(n) = 1/(N - n) Σ_{j=1}^{N-n} [p_c(j+n) - p_c(j)]^2 + [q_c(j+n) - q_c(j)]^2,
//
// for n <= n_cut = N/10 (so that every average has many terms), minus the oscillatory term the
// mean of φ contributes, V_osc(c, n) = (E φ)^2 (1 - cos n c)/(1 - cos c): D_c(n) = M_c(n) - V_osc
// (the "modified mean-square displacement", which has the same asymptotic growth but converges
// faster). K_c is the correlation coefficient of n and D_c(n); it tends to 1 for linear growth
// (chaos) and to 0 for bounded D_c (regular motion). Isolated values of c resonate with a
// frequency of the motion and give a spurious large K_c, so the result is the median of K_c over
// random c drawn uniformly from (c_min, c_max) = (π/5, 4π/5) by default, which avoids the
// resonances at c = 0 and π.
//
// The series should not be oversampled: for a flow, sample it at a Poincaré section or at
// intervals comparable to the correlation time, not at integrator steps (Gottwald & Melbourne
// 2009, §5). A series of a few thousand samples is usually enough.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pwl::analysis {

struct ZeroOneOptions {
  int frequencies = 100;  // how many random c (>= 1)
  double c_min = 0.6283185307179586;  // π/5
  double c_max = 2.5132741228718345;  // 4π/5; 0 < c_min < c_max < π
  std::uint64_t seed = 1;  // fixes the c's, so that results are reproducible
  // n_cut as a fraction of N (0 < fraction <= 0.5); at least 2 lags are used.
  double lag_fraction = 0.1;
  // Below this many samples the test is refused (InputError): the correlation over n <= n_cut
  // needs enough lags and every M_c(n) enough terms.
  int min_samples = 100;
  // A series whose standard deviation is at most constant_tolerance * max(|mean|, tiny) is
  // treated as constant: D_c is then rounding noise, whose correlation means nothing, so K = 0.
  double constant_tolerance = 1e-12;

  bool is_valid(std::string* why) const;
};

struct ZeroOneResult {
  double K = 0.0;               // median of K_c: ≈ 0 regular, ≈ 1 chaotic
  std::vector<double> c;        // the frequencies used
  std::vector<double> K_c;      // the correlation for each (same order)
  int lags = 0;                 // n_cut
  bool constant_series = false; // the series was (numerically) constant, K set to 0
};

// Throws InputError for invalid options, fewer than min_samples values, or a non-finite value
// (the message names series[i] and the value).
ZeroOneResult zero_one_test(std::span<const double> series, const ZeroOneOptions& options = {});

}  // namespace pwl::analysis
