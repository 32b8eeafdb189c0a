#pragma once
// The reference motion of one degree of freedom of a chain, computed once and read at any time:
// the errors of `pwl bench chain` and of figures 8-9 are measured against it.
//
// A kink-located Runge-Kutta integration (reference_integrator.hpp) ends a step exactly at every
// spring opening or closing, and is advanced over a fine grid, so that between two recorded
// points the motion is smooth and short. Every step end is recorded with the displacement,
// velocity and acceleration of the degree of freedom, and the motion in between is the quintic
// Hermite interpolant of those (error O(h^6) in x and O(h^5) in x' for spacing h; x' across the
// nanosecond intervals between nearly coinciding events from x' and x'' alone). Methods are then
// compared at their own step times, without forcing their steps onto a common grid.
#include <string>
#include <vector>

#include "pwl/integrators/method_table.hpp"
#include "pwl/model/gap_structure.hpp"

namespace pwl::app {

class ReferenceTrack {
 public:
  // Integrates `structure` from rest over [0, t_end], recording degree of freedom `dof` at every
  // step end of the reference integrator, which is advanced over a grid of spacing `grid`. The
  // settings must build an integrator that ends a step at every spring switch
  // (locates_switches), or the interpolant would cross kinks: InputError otherwise.
  static ReferenceTrack compute(const GapStructure& structure, double t_end,
                                const MethodSettings& settings, double grid, Index dof);

  double position(double t) const;
  double velocity(double t) const;
  double t_end() const { return t_.empty() ? 0.0 : t_.back(); }
  std::size_t size() const { return t_.size(); }
  double seconds() const { return seconds_; }  // wall time of the integration

  // Largest |x| and |x'| difference from `other`, at this track's points.
  std::pair<double, double> difference(const ReferenceTrack& other) const;

  // A CSV cache: t, x, x', x'' per row, with a first line that names what was computed. load
  // returns false when the file is missing or was computed for something else.
  void save(const std::string& path, const std::string& label) const;
  bool load(const std::string& path, const std::string& label);

 private:
  // Quintic Hermite on the interval holding t: value (derivative = 0) or first derivative (1).
  double interpolate(double t, int derivative) const;
  std::vector<double> t_, x_, v_, a_;
  double seconds_ = 0.0;
};

// One method's record of x and x' of a degree of freedom at its step times.
struct TrackRecord {
  std::vector<double> t, x, v;
  void add(double time, double position, double velocity) {
    t.push_back(time);
    x.push_back(position);
    v.push_back(velocity);
  }
};

// Largest |x - x_ref| and |x' - x'_ref| over a record.
std::pair<double, double> largest_errors(const TrackRecord& record, const ReferenceTrack& reference);

}  // namespace pwl::app
