// The band check's pairing of the multipliers near the unit circle between the two ends of a
// continuation step (analysis/src/orbits/multiplier_movement.hpp), on sets whose answer is known
// by hand: within half the margin or not, a turn at a constant modulus, one to one in a crowd
// (where nearest neighbours alone would pass), an augmenting path where the first choice blocks
// the second, both ends in turn, multipliers far from the circle ignored, a NaN never trusted;
// and the band the reported multipliers cover (watched_band).
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <limits>
#include <vector>

#include "orbits/multiplier_movement.hpp"

using pwl::orbits::FloquetMultipliers;
using pwl::orbits::detail::band_stayed;
using pwl::orbits::detail::watched_band;
using C = std::complex<double>;
using Set = std::vector<C>;

namespace {

// Both orders of the ends give the same answer.
bool stayed(const Set& a, const Set& b, double margin) {
  const bool forward = band_stayed(a, b, margin);
  CHECK(forward == band_stayed(b, a, margin));
  return forward;
}

}  // namespace

TEST_CASE("the band check pairs the multipliers near the circle one to one within half the margin",
          "[orbits]") {
  const double margin = 0.1;  // near: ||μ| − 1| <= 0.05; a partner within 0.05
  SECTION("within half the margin, or not") {
    CHECK(stayed({C(0.99, 0)}, {C(0.99, 0)}, margin));
    CHECK(stayed({C(0.99, 0)}, {C(1.03, 0)}, margin));
    CHECK_FALSE(stayed({C(0.99, 0)}, {C(1.045, 0)}, margin));
    CHECK_FALSE(stayed({C(0.99, 0)}, {C(0.99, 0.06)}, margin));
    // Complex pairs turned a little: each member pairs with its own.
    const C mu = std::polar(0.995, 0.8), nu = std::polar(1.01, 0.83);
    CHECK(stayed({mu, std::conj(mu)}, {nu, std::conj(nu)}, margin));
  }
  SECTION("a turn at nearly the same modulus is no movement across the band") {
    // A long wave of a long chain: 3e-4 rad further round as the period changed, its modulus
    // 1e-7 larger, against a band of 2e-5 (a partner within 1e-5): it stayed.
    const C wave = std::polar(1.0 - 5e-6, 0.003), turned = std::polar(1.0 - 4.9e-6, 0.0033);
    CHECK(stayed({wave, std::conj(wave)}, {turned, std::conj(turned)}, 2e-5));
    // Turned by more than kBandTurn, or its modulus moved by more than half the margin: not.
    CHECK_FALSE(stayed({wave}, {std::polar(1.0 - 5e-6, 0.003 + 0.03)}, 2e-5));
    CHECK_FALSE(stayed({wave}, {std::polar(1.0 - 2e-5, 0.0033)}, 2e-5));
    // One pair goes out while another comes in elsewhere on the circle: the same moduli at both
    // ends, the same count outside, but neither pair has a partner (a stable window in between).
    const C out_a = std::polar(1.03, 0.5), in_a = std::polar(0.96, 1.2);
    const C in_b = std::polar(0.96, 0.5), out_b = std::polar(1.03, 1.2);
    CHECK_FALSE(stayed({out_a, std::conj(out_a), in_a, std::conj(in_a)},
                       {in_b, std::conj(in_b), out_b, std::conj(out_b)}, margin));
  }
  SECTION("one to one: two near the circle are not both explained by one") {
    // Nearest neighbours would pass: 0.98 and 0.99 are each within 0.01 of 0.985.
    CHECK_FALSE(stayed({C(0.98, 0), C(0.99, 0)}, {C(0.985, 0), C(0.5, 0)}, margin));
    CHECK(stayed({C(0.98, 0), C(0.99, 0)}, {C(0.985, 0), C(0.975, 0)}, margin));
  }
  SECTION("an augmenting path where the first choice blocks the second") {
    // 0.96 reaches 0.99 (0.03) and 0.92 (0.04); 1.0 reaches only 0.99. Taken in order, 0.96 takes
    // 0.99 first and must give it up to 1.0 for 0.92.
    CHECK(stayed({C(0.96, 0), C(1.0, 0)}, {C(0.99, 0), C(0.92, 0)}, margin));
    CHECK_FALSE(stayed({C(0.96, 0), C(1.0, 0)}, {C(0.99, 0), C(0.90, 0)}, margin));
  }
  SECTION("multipliers far from the circle at both ends are not checked") {
    CHECK(stayed({C(0.5, 0), C(2.0, 0)}, {C(0.3, 0), C(3.0, 0)}, margin));
    CHECK(stayed({C(0.9, 0)}, {C(0.94, 0)}, margin));  // 0.94 is 0.06 inside: not near
  }
  SECTION("one that comes near the circle must have come from within half the margin") {
    CHECK_FALSE(stayed({C(0.9, 0)}, {C(0.96, 0)}, margin));  // came 0.06
    CHECK(stayed({C(0.92, 0)}, {C(0.96, 0)}, margin));       // came 0.04
  }
  SECTION("a multiplier that is not a number is never trusted") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK_FALSE(band_stayed({C(nan, 0)}, {C(0.99, 0)}, margin));
    CHECK_FALSE(band_stayed({C(0.99, 0)}, {C(nan, 0)}, margin));
  }
  SECTION("nothing near the circle, or nothing at all") {
    CHECK(stayed({}, {}, margin));
    CHECK(stayed({C(0.2, 0)}, {}, margin));
    CHECK_FALSE(stayed({C(1.0, 0)}, {}, margin));
  }
}

TEST_CASE("the band the reported multipliers cover reaches down to the smallest of them",
          "[orbits]") {
  FloquetMultipliers mu;
  mu.complete = false;
  SECTION("the leading ones: down to the smallest modulus, in any order") {
    mu.values = {C(1.2, 0), std::polar(0.97, 0.4), std::polar(0.97, -0.4), C(-0.99, 0)};
    CHECK(watched_band(mu) == Approx(0.03).epsilon(1e-12));
  }
  SECTION("every multiplier of the structure: the whole band") {
    mu.values = {C(0.5, 0), C(0.2, 0)};
    mu.complete = true;
    CHECK(watched_band(mu) == 1.0);
  }
  SECTION("none reported, or all of them outside the circle: no band to check") {
    CHECK(watched_band(mu) == 0.0);
    mu.values = {C(1.3, 0), C(1.1, 0)};
    CHECK(watched_band(mu) < 0.0);
  }
}
