#pragma once
// Rotation numbers as fractions p/q: the period of an orbit locked on a torus, and the p/q a
// long-period verdict turns by.
//
// An orbit locked on a torus has rotation number p/q to the precision of the averages that
// measure it (weighted_birkhoff.hpp), while a typical irrational rotation has no fraction much
// closer than Dirichlet's bound 1/q². locked_denominator asks a thousand times closer than that
// bound (kLocked): measured on the (θ, α) map of figure 5's chain, the cell α = 5, θ = 1.81 by the
// exact solver has ρ = 0.3013698628 against 22/73 = 0.3013698630 (1e-6 of 1/q²), while the torus at
// θ = 1.8, whose ρ = 0.3063343651 lies 6.6e-9 from 295/963 (6e-3 of 1/q²), is not taken for a
// locked orbit. Continued fractions: A. Ya. Khinchin, Continued Fractions, Dover 1997, ch. 1-2.
#include <string>

namespace pwl::analysis {

constexpr double kLocked = 1e-3;
constexpr int kLockedPeriodLimit = 1000;

// The denominator of the first continued-fraction convergent p/q of `rho` with
// |rho − p/q| <= kLocked / q², if q <= limit; 0 otherwise (also for a rho that is not finite).
int locked_denominator(double rho, int limit);

// The rotation of a period-q orbit as "p/q" (p = round(rho q), not reduced: the orbit closes after
// q periods having turned p times), or empty when rho is not within kLocked / q² of p/q or not
// finite, or q < 1.
std::string rotation_fraction(double rho, int q);

}  // namespace pwl::analysis
