#pragma once
// The files of pwl continue --curves (bifurcation curves in two parameters): curves.csv and
// codim2.csv written a row at a time as the curves grow, progress on standard error, the summary
// printed, and the figure of the curves in the plane (bifurcation_curves.png and .svg).
//
//   curves.csv  curve,type,<P>,<Q>,period,spring,multiplier_re,multiplier_im,kappa,
//               amplitude_x1..amplitude_xn,x1..xn,v1..vn
//               one row per point of a curve: its start (a bifurcation of the branch), the points
//               toward larger Q; its start again, the points toward smaller Q. spring is 1-based
//               (grazing curves), the multiplier the one the curve's condition puts on the unit
//               circle (+1, −1, e^{iω}; empty for grazing), kappa = cos ω (Neimark–Sacker), and
//               the orbit's state at t = 0 mod kT, from which any point can be solved again.
//   codim2.csv  type,<P>,<Q>,curves,detail
//               one row per codimension-two point, the curves it was found on joined by ';'.
#include <string>
#include <vector>

#include "output/csv_writer.hpp"
#include "output/progress_line.hpp"
#include "pwl/orbits/bifurcation_curves.hpp"

namespace pwl::app {

class CurveOutputs : public orbits::CurvesObserver {
 public:
  CurveOutputs(const std::string& folder, const orbits::CurvesOptions& options, int dofs,
               bool progress);
  void point(const orbits::CurvePointRecord& point) override;
  void codim2(const orbits::Codim2Point& point) override;
  // Ends the progress line.
  void finish_progress();
  long rows() const { return curves_.rows(); }

 private:
  const orbits::CurvesOptions& options_;
  int dofs_;
  std::string folder_;
  FlushedCsv curves_;
  FlushedCsv codim2_;
  ProgressLine progress_;
  int last_curve_ = -1;
};

// Stops the run on SIGINT or SIGTERM (parallel/stop_signals.hpp) between two rows: throws Stopped
// saying that every row written in `folder` is whole.
void stop_on_signal(const std::string& folder);

// The columns of curves.csv and codim2.csv.
std::vector<std::string> curve_columns(const orbits::CurvesOptions& options, int dofs);
std::vector<std::string> codim2_columns(const orbits::CurvesOptions& options);

// The curves and codimension-two points, for people.
void print_curves(const orbits::CurvesResult& result, const orbits::CurvesOptions& options);

// OUT/bifurcation_curves.png and .svg: the curves in the plane (P, Q), each type in its own style,
// the codimension-two points marked.
void draw_curves(const std::string& folder, const orbits::CurvesOptions& options,
                 const orbits::CurvesResult& result, const std::string& title);

}  // namespace pwl::app
