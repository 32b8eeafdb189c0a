#pragma once
// The invariant-curve (torus) test by weighted Birkhoff averages, on a sequence of Poincaré points.
//
// Das, Sander, Yorke & Meiss, Nonlinearity 30 (2017) 4111 ("Quantitative quasiperiodicity"); Das &
// Yorke, Nonlinearity 31 (2018) 491 (the super-convergence proof); Sander & Meiss, Physica D 411
// (2020) 132569 (rotation numbers of invariant circles and the digits as a chaos indicator).
//
// The plain time average (1/N) Σ f(p_n) of an observable f along an orbit converges like 1/N on a
// quasi-periodic orbit and like 1/sqrt(N) on a chaotic one. Weighting the terms with a bump that
// vanishes with all its derivatives at both ends of the record,
//
//     WB_N(f) = Σ_{n<N} w(n/N) f(p_n) / Σ_{n<N} w(n/N),   w(t) = exp(-1/(t(1-t))) on (0, 1),
//
// removes the end effects that limit the plain average: on a smooth (C^∞ or analytic) invariant
// curve or torus whose rotation is Diophantine and for smooth f, WB_N(f) converges faster than any
// power of N, reaching rounding error after a thousand or so points. On a chaotic orbit the
// weights do not help (the terms decorrelate, the error stays ~ 1/sqrt(N)).
//
// The test compares the average over the first half of the record, points [0, N/2), with the
// average over the second half, [N/2, N), each with its own weights, and reports the number of
// digits on which they agree,
//
//     digits(f) = -log10( max(|WB_first(f) - WB_second(f)| / spread(f), ε) ),
//
// where spread(f) = max f - min f over all N points (so that digits do not depend on units or on
// the amplitude of the motion) and ε the machine epsilon (so that digits <= 15.65). `digits` is
// the minimum over the observables. What to expect (measured in tests/analysis/
// weighted_birkhoff_test.cpp, see torus_digits): 7 to 10 digits on a smooth invariant curve with a
// noble rotation number from 1000 points, 11 to 13 from 2000; 1 to 2.5 on a chaotic orbit, growing
// only like (1/2) log10 N.
//
// A periodic orbit repeats its points, so its two halves also agree to rounding and it scores as
// many digits as a torus: this test does not tell periodic from quasi-periodic motion. Run the
// period search (period_detection.hpp) first and use this test only when no period is found.
// A rotation close to a low-order rational (a long period, or a torus near a resonance) converges
// more slowly and scores fewer digits for a given N; so do a torus about to break up and data
// with noise (about -log10(noise / spread) digits at most).
//
// Smoothness. Super-convergence needs the curve, the dynamics on it (its conjugacy to a rotation)
// and f to be smooth; with only finitely many derivatives the error falls like a power of N
// (Das & Yorke 2018). The stroboscopic map of a structure with gap springs is only piecewise
// smooth (its derivatives jump where a spring switches), so its invariant curves may score
// fewer digits than the smooth examples the threshold below was measured on; check the digits of
// known quasi-periodic responses of the structures at hand before relying on the verdict.
// Measured on the paper's 5-DOF chain (figure 5's: ζ = 0.2, Δ̃ = 0; the exact solver, the
// points after 500 periods, the default observables; digits at N = 500 / 1000 / 2000 / 4000):
//   α = 5, θ = 1.8, whose points trace one smooth loop (of the same size after 26000 periods):
//     3.8 / 4.4 / 5.4 / 5.9
//   figure 6's chaos (α = 15, θ = 1.5, λ1 ≈ 0.33 a period): 1.3 / 1.9 / 1.8 / 1.8
//   period-2 (α = 3, θ = 1) and period-4 (α = 10, θ = 2.2) records:
//     12.8 / 12.3 / 12.1 / 11.8 and 7.5 / 9.3 / 11.8 / 11.5
// and the rotation number in the (x1, x2) plane: the loop's ρ = 0.3063 to 6.1 / 6.2 / 7.2 / 7.8
// digits, the chaos's to 1.7 / 2.0 / 2.0 / 4.1. The loop gains about 0.6 digits per doubling of
// N, the smooth curves of the tests 1.2 to 3: on these structures torus_digits = 6 is reached
// only from about 4000 points, and at a few hundred points a torus and chaos differ by about 2
// digits (the rotation digits by about 4).
//
// The observables. By default, for every coordinate i of the points, with u_i the coordinate
// scaled to [0, 1] over the record (u_i = (x_i - min x_i) / (max x_i - min x_i)):
//
//     x_i,   cos(π u_i),   sin(π u_i)
//
// (the coordinate itself and two smooth nonlinear functions of it, so that an average that agrees
// by symmetry for one function is checked by others). An observable that is constant over the
// record (spread <= constant_tolerance * max |f|, rounding noise) carries no information and is
// left out. Options.observables replaces the defaults by the caller's functions.
//
// The rotation number. In the plane of two coordinates (plane_first, plane_second) each point is
// seen from the weighted-Birkhoff centre c = WB_N(p) (the average of the points under the orbit's
// invariant measure, which, unlike the arithmetic mean, converges as fast as the other averages),
// at the angle θ_n = atan2(y_n - c_y, x_n - c_x). The increments Δθ_n = θ_{n+1} - θ_n are taken
// on one branch of width 2π (see below), and
//
//     ρ = WB_{N-1}(Δθ / 2π)  mod 1, in [0, 1),
//
// in turns per iteration; rotation_digits compares the first and second halves of the N - 1
// increments in the same way as for the observables, with the spread taken as one turn (ρ is
// already scale-free). This assumes that the points lie on a closed curve that, seen in that
// plane, winds once around c, as a curve star-shaped around c does (every ray from c crosses it
// once); the increment is then a smooth function on the curve and ρ its rotation number. How it
// fails, and how a caller sees it:
//  - the points are not on a curve (chaos), the projected curve passes through or close to c, or
//    the increments spread over more than one turn (a curve that does not go around c, such as a
//    crescent with c in its hollow): Δθ is not a smooth function on the curve, and
//    rotation_digits comes out low (2 to 3 in the tests) while `digits` may be high; a high
//    `digits` with a low `rotation_digits` means a good curve seen in a bad plane: choose other
//    coordinates;
//  - the projection winds k times around c (it crosses itself, like a limaçon with an inner
//    loop): the average converges, with many digits, to k ρ mod 1. The digits cannot tell this
//    apart; a plot of the projected points, or another plane, can.
// On a torus of higher dimension (several incommensurate frequencies besides the forcing) the
// digits are high too, and ρ is then the rotation of its projection, not one frequency ratio.
//
// The branch of Δθ. A circle map's increments lie in an arc shorter than one turn, which for a
// rotation number close to 0 is inside (-π, π], the usual choice; but for a rotation near 1/2 a
// non-uniform curve has increments on both sides of ±π, and cutting there would mix increments of
// about +1/2 and -1/2 turn. So the cut is put in the middle of the widest arc of directions that
// no increment takes, and the increments are taken in the branch (cut - 2π, cut]. Whenever the
// increments all lie in (-π, π) and leave an arc around ±π free that is the usual (-π, π].
#include <functional>
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::analysis {

// An observable: a real function of one point (the point has the dimension of the input's rows).
using PointObservable = std::function<double(const Vector& point)>;

struct WeightedBirkhoffOptions {
  // Below this many points the test is refused (InputError). Each half must hold enough points
  // for the weights to act: 200 points give about 4 to 5 digits on a smooth curve, already above
  // chaos, but about 1000 are needed for a clear verdict (see torus_digits).
  int min_points = 200;  // >= 20
  // `smooth_invariant_curve` is set when digits >= torus_digits (0 < torus_digits <= 15).
  //
  // Why 6. Measured in tests/analysis/weighted_birkhoff_test.cpp, digits at N = 250 / 500 / 1000
  // / 2000 points:
  //   smooth curves   golden-mean rigid rotation        5.9 / 7.5 / 10.0 / 12.6
  //                   Arnold circle map, K = 0.5, ρ = 2 - golden mean   4.7 / 6.3 / 9.2 / 12.2
  //                   the same, ρ ≈ 0.4512 (near 1/2)   4.3 / 6.4 / 8.8 / 10.8
  //                   standard map K = 2, circle through (π + 0.6, 0)   3.7 / 5.4 / 7.4 / 11.3
  //   chaos           Hénon a = 1.4, b = 0.3           1.9 / 1.7 / 1.9 / 2.3 (2.4 at 16000)
  //                   standard map K = 2 from (0.1, 0.1)                 0.9 / 1.2 / 1.4 / 1.5
  // A chaotic orbit gains about half a digit per tenfold N (its error falls like 1/sqrt(N)), so
  // it would need of the order of 10^10 points to reach 6; three of the four smooth curves pass
  // 6 at 500 points and all four from 1000. 8, the figure one might expect, misses the standard
  // map's circle at 1000 points and every curve at 500; 6 keeps a margin of 3.5 digits over the
  // chaotic orbits and still calls every curve above a curve from 1000 points. With fewer than
  // 1000 points (the sweep default records 500) the verdict is marginal: record more points, or
  // combine the raw digits with the other indicators. Orbits that stick for long near islands
  // (Hamiltonian systems) can score more than chaos usually does.
  double torus_digits = 6.0;
  // The plane of the rotation number: two distinct coordinates (indices into a point), each less
  // than the points' dimension.
  int plane_first = 0;
  int plane_second = 1;
  // Whether to measure the rotation number (needs points of dimension >= 2).
  bool rotation = true;
  // An observable whose spread over the record is at most constant_tolerance * max |f| (or 0) is
  // constant up to rounding and is left out (0 <= constant_tolerance < 1).
  double constant_tolerance = 1e-12;
  // The observables; empty means the default three per coordinate (above). Every entry must be
  // callable (not an empty std::function).
  std::vector<PointObservable> observables;

  bool is_valid(std::string* why) const;
};

struct WeightedBirkhoffResult {
  // min over the observables used of digits(f); ε-capped at -log10(ε) ≈ 15.65. When no observable
  // varied (all points equal up to rounding), digits is that cap and observables_used is 0.
  double digits = 0.0;
  // digits >= torus_digits, and at least one observable varied: the points lie, to the precision
  // the digits say, on a smooth invariant curve (or torus) with an irrational rotation, or on a
  // periodic orbit (tell the two apart by the period search first). A record with no varying
  // observable (a fixed point) is not called a curve.
  bool smooth_invariant_curve = false;
  // The rotation number, in turns per iteration in [0, 1), and the digits on which its two halves
  // agree (0 when the rotation was not measured; then has_rotation is false).
  bool has_rotation = false;
  double rotation_number = 0.0;
  double rotation_digits = 0.0;
  double rotation_difference = 0.0;  // |ρ_first - ρ_second|, in turns
  // The weighted-Birkhoff centre of the points (dimension of the points); c in the plane above.
  Vector centre;
  int points = 0;            // N, the number of points used
  int observables_used = 0;  // how many observables varied and entered `digits`
  // Per observable (in the order of options.observables, or coordinate-major x_i, cos, sin for the
  // defaults): WB_N over all points, the relative half difference |WB_first - WB_second| / spread
  // (0 for an observable left out as constant), its digits (the cap when left out), and whether
  // it was used.
  std::vector<double> averages;
  std::vector<double> relative_differences;
  std::vector<double> observable_digits;
  std::vector<bool> observable_used;
};

// The normalised bump weights w(n/N) / Σ_j w(j/N), n = 0 .. N-1 (w(0) = 0). N >= 2.
std::vector<double> weighted_birkhoff_weights(int N);

// WB_N of a sequence of values (the weights above with N = values.size() >= 2).
double weighted_birkhoff_average(const std::vector<double>& values);

// The test on N points, one per row of `points` (N x d). Throws InputError for invalid options,
// fewer than min_points rows, zero columns, a non-finite entry (named points(row, column) with its
// value), a plane index that is not a coordinate of the points, or an observable that returns a
// non-finite value (named observables[k] with the row).
WeightedBirkhoffResult weighted_birkhoff_test(const Matrix& points,
                                              const WeightedBirkhoffOptions& options = {});

}  // namespace pwl::analysis
