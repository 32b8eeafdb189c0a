#pragma once
// What the study-pipeline tests (tests/study) share: the paper's figure-5 chain at a cell of the
// (θ, α) map, a record by the exact solver, an observer that keeps the recorded stroboscopic
// states, and points as matrix rows.
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/study/sweep_point.hpp"
#include "pwl/types.hpp"

namespace pwl::test {

// The paper's 5-DOF chain of figure 5 (ζ = 0.2, Δ̃ = 0, loads 1, −1, 1, −1, 1) at α and θ: the
// structure of apps/scenes/theta_alpha_map.toml.
inline NondimensionalChain figure5_cell(double alpha, double theta) {
  NondimensionalChain c = paper_five_dof_case("5");
  c.alpha = {alpha};
  c.theta = theta;
  return c;
}

// A record by the exact event-driven solver, λ1 by two nearby trajectories (it has no step to
// take a tangent of), every step of the ladder off.
inline analysis::PointSettings exact_record(int transient, int recorded) {
  analysis::PointSettings s;
  s.transient_periods = transient;
  s.recorded_periods = recorded;
  s.method = MethodSettings{Method::exact};
  s.lyapunov_estimate = analysis::LyapunovEstimate::two_trajectories;
  return s;
}

// Keeps every recorded stroboscopic state [x; v] of a point's evaluation.
struct StateRecorder : analysis::PointObserver {
  std::vector<Vector> states;
  void poincare_point(int, double, const Vector& state) override { states.push_back(state); }
};

// One point a row.
inline Matrix as_rows(const std::vector<Vector>& points) {
  Matrix m(static_cast<Index>(points.size()), points.empty() ? 0 : points.front().size());
  for (std::size_t i = 0; i < points.size(); ++i) m.row(static_cast<Index>(i)) = points[i];
  return m;
}

}  // namespace pwl::test
