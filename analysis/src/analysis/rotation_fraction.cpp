// Rotation numbers as fractions (see the header): continued-fraction convergents.
#include "pwl/analysis/rotation_fraction.hpp"

#include <fmt/format.h>

#include <cmath>

namespace pwl::analysis {

int locked_denominator(double rho, int limit) {
  if (!std::isfinite(rho)) return 0;
  // Convergents h/k of ρ: h_{-1} = 1, h_{-2} = 0; k_{-1} = 0, k_{-2} = 1.
  double x = rho;
  long h0 = 0, h1 = 1, k0 = 1, k1 = 0;
  for (int i = 0; i < 40; ++i) {
    const double a = std::floor(x);
    const long h = static_cast<long>(a) * h1 + h0;
    const long k = static_cast<long>(a) * k1 + k0;
    if (k > limit) return 0;
    const double q = static_cast<double>(k);
    if (k >= 1 && std::abs(rho - static_cast<double>(h) / q) <= kLocked / (q * q)) {
      return static_cast<int>(k);
    }
    const double fraction = x - a;
    if (fraction <= 0.0) return 0;
    x = 1.0 / fraction;
    h0 = h1;
    h1 = h;
    k0 = k1;
    k1 = k;
  }
  return 0;
}

std::string rotation_fraction(double rho, int q) {
  if (!std::isfinite(rho) || q < 1) return {};
  const double Q = static_cast<double>(q);
  const double p = std::round(rho * Q);
  if (std::abs(rho - p / Q) > kLocked / (Q * Q)) return {};
  return fmt::format("{}/{}", static_cast<long>(p), q);
}

}  // namespace pwl::analysis
