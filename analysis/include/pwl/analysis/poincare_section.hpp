#pragma once
// Poincaré sections of a sampled flow: where a trajectory known only at discrete times crosses a
// hyperplane, and its states at the multiples of a forcing period.
//
// Integrators report states at the ends of their steps; the section points fall in between. Linear
// interpolation between two samples gives the crossing to O(h^2) in the step h. When the
// derivatives at the samples are known too (the velocity for the displacement, the acceleration
// for the velocity), the cubic Hermite interpolant matches value and slope at both ends and
// gives O(h^4) (Hairer, Nørsett & Wanner, Solving ODEs I, §II.6, on dense output), which is what
// a high-order integrator's accuracy deserves.
//
// Crossings are counted on half-open steps (t0, t1]: a sample lying exactly on the hyperplane
// counts for the step that ends there, never also for the next one, so a point on the section
// is reported once.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::analysis {

enum class CrossingDirection {
  up,    // the component increases through the level
  down,  // it decreases through the level
  both,
};

// The hyperplane state[component] = level.
struct HyperplaneSection {
  Index component = 0;
  double level = 0.0;
  CrossingDirection direction = CrossingDirection::up;

  bool is_valid(std::string* why) const;
};

struct Crossing {
  double t = 0.0;
  Vector state;       // interpolated; state[component] is set to level exactly
  bool upward = true; // the direction of this crossing
};

// The crossing of the segment between (t0, s0) and (t1, s1) with the section, interpolated
// linearly; nullopt when the signs of s[component] - level at the two ends show no crossing in
// the requested direction. Throws InputError for an invalid section, t1 <= t0, states of different
// sizes, a component out of range, or a non-finite value.
std::optional<Crossing> find_crossing(const HyperplaneSection& section, double t0, const Vector& s0,
                                      double t1, const Vector& s1);

// The same on the cubic Hermite interpolant built from the states and their time derivatives
// ds0 = s'(t0), ds1 = s'(t1). The interpolant is split at its turning points into monotone
// pieces and the first piece that crosses the level in the requested direction is solved by
// safeguarded Newton iteration, so a crossing and re-crossing inside one step (the interpolant
// bulging over the level between two samples on the same side) is found too, and the earliest
// crossing is the one reported.
std::optional<Crossing> find_crossing(const HyperplaneSection& section, double t0, const Vector& s0,
                                      const Vector& ds0, double t1, const Vector& s1,
                                      const Vector& ds1);

// All crossings along a sampled trajectory, one step at a time (at most one per step), linearly
// or, when derivatives is not empty, Hermite-interpolated. times must increase strictly.
std::vector<Crossing> find_crossings(const HyperplaneSection& section,
                                     const std::vector<double>& times,
                                     const std::vector<Vector>& states,
                                     const std::vector<Vector>& derivatives = {});

// The Poincaré section a job records, as the command line's --section and --phase give it.
//
// The stroboscopic section samples the state at t = (k + phase) T, k = 0, 1, ...: once per
// forcing period T at a fixed phase of the loads (phase a fraction of T, 0 <= phase < 1). It is
// the section of the period map, and the regime of a motion (period-k, quasi-periodic, chaotic),
// λ1 and K are properties of that map: whichever section a job records, it classifies the motion
// on the stroboscopic points at `phase`. A hyperplane section records, instead, every crossing of
// state[component] = level in the chosen direction, whenever it happens (v_i = 0 going down: the
// largest excursions of mass i); it changes which points are recorded, written and drawn, not the
// classification.
struct PoincareSection {
  enum class Kind { stroboscopic, hyperplane };
  Kind kind = Kind::stroboscopic;
  double phase = 0.0;            // of the stroboscopic points, in [0, 1)
  HyperplaneSection hyperplane;  // when kind == hyperplane

  bool stroboscopic() const { return kind == Kind::stroboscopic; }
  // The stroboscopic section at phase 0 (t = kT), what every job records unless told otherwise.
  bool is_default() const { return stroboscopic() && phase == 0.0; }
  // Ceres-style check for a state of 2 `dofs` components: false with a message naming the field
  // and its value (a phase outside [0, 1), a component out of range, a level that is not finite).
  bool is_valid(Index dofs, std::string* why) const;
  // The command line's spelling: "strobe", or the hyperplane as "v3=0,down" (components named
  // x1..xn, v1..vn for n = dofs; the level in its shortest exact decimal form).
  std::string text(Index dofs) const;
  // For figure labels and messages: "t = kT", "t = (k + 0.25)T", "v3 = 0 going down".
  std::string label(Index dofs) const;
};

// The section named by `text`: "strobe", or "<c><i>=<level>,<direction>" with c = x (a
// displacement) or v (a velocity), i = 1..dofs, a finite level and the direction up, down or both
// ("v3=0,down", "x2=0.1,up"; blanks around the parts are ignored). The phase is left at 0. Throws
// InputError saying what is wrong with the text (the caller names its flag and the value).
PoincareSection parse_poincare_section(std::string_view text, Index dofs);

// A mechanical state sample: displacements x and velocities v at time t, and optionally the
// accelerations a (empty when not known).
struct StateSample {
  double t = 0.0;
  Vector x;
  Vector v;
  Vector a;
};

// The state at time t between two samples a and b (a.t < t < b.t; at either end, that sample),
// by the interpolation stroboscopic_samples uses: displacements cubic-Hermite from x and v,
// velocities cubic-Hermite from v and a when both samples carry accelerations (O(h^4)) and
// otherwise the derivative of the displacement interpolant (O(h^3)), accelerations linearly when
// present. The result's t is t. Throws InputError for samples of different sizes or t outside
// [a.t, b.t].
StateSample interpolate_state(const StateSample& a, const StateSample& b, double t);

struct StroboscopicOptions {
  // A target time within snap_tolerance * (local step length) of a sample takes that sample
  // exactly, with no interpolation error at all; integrators whose step divides the period land
  // on the targets up to rounding.
  double snap_tolerance = 1e-9;

  bool is_valid(std::string* why) const;
};

// The states at t = t0 + k T (k = 0, 1, ...) for every such time within [samples.front().t,
// samples.back().t], with t set to t0 + k T (computed so, not accumulated, to avoid drift).
// Between samples the displacements are cubic-Hermite-interpolated from x and v (O(h^4)); the
// velocities from v and a when both samples carry accelerations (O(h^4)), otherwise by
// differentiating the displacement interpolant (O(h^3)); accelerations are interpolated linearly
// when present. Throws InputError for a non-positive or non-finite period, samples not strictly
// increasing in t, or inconsistent sizes.
std::vector<StateSample> stroboscopic_samples(const std::vector<StateSample>& samples, double t0,
                                              double period, const StroboscopicOptions& options = {});

// The same, fed one sample at a time, for example from an integrator's step observer:
//
//     StroboscopicSampler sampler(0.0, 2 * pi / omega);
//     integrator.advance_to(t_end, [&](double t, const Vector& x, const Vector& v) {
//       sampler.observe(t, x, v);
//     });
//     for (const StateSample& s : sampler.samples()) ...
class StroboscopicSampler {
 public:
  // Throws InputError for a non-positive or non-finite period or invalid options.
  StroboscopicSampler(double t0, double period, const StroboscopicOptions& options = {});

  // Takes the next sample (t must exceed the previous one's); a is optional.
  void observe(double t, const Vector& x, const Vector& v, const Vector& a = Vector());
  const std::vector<StateSample>& samples() const { return samples_; }
  void clear_samples() { samples_.clear(); }

 private:
  double t0_;
  double period_;
  StroboscopicOptions options_;
  long next_k_ = 0;  // the next target is t0 + next_k_ * period (after the first sample)
  bool has_previous_ = false;
  bool stepped_ = false;  // the first step (when a target just before the first sample snaps)
  StateSample previous_;
  std::vector<StateSample> samples_;
};

}  // namespace pwl::analysis
