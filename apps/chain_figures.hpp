#pragma once
// The paper's figures 7-9 (He, Gao & Zhong 2018, section 4.2; SPEC.md §5) for its 1000-mass chain:
//   fig7.png  phase portrait of mass 1 for t in [100, 200] s, by the banded PIM (η = 0.02 s)
//   fig8.png  error of x1 and x1' of the banded PIM against the reference
//   fig9.png  the same for dopri5 at tolerance 1e-5 (plain, like the paper's ode45)
// The reference is a kink-located rkf78 run at tolerance 1e-12 (bench_reference.hpp), where the
// paper used ode45 at 1e-10.
#include <string>

namespace pwl::app {

// The largest errors the figures show, for the report.
struct ChainFigureSummary {
  int masses = 0;
  double pim_error_x = 0, pim_error_v = 0;  // banded PIM, m and m/s
  double rk_error_x = 0, rk_error_v = 0;    // dopri5 at 1e-5
  bool drawn = false;                       // whether gnuplot drew the three PNGs
};

// Computes what the figures plot, writes it under plots_dir/data and draws the three PNGs into
// plots_dir with the scripts plots/fig7_phase_mass1.gp and plots/fig8_9_errors.gp. quick: 200
// masses and a reference at 1e-10, for smoke runs (the titles say so).
ChainFigureSummary reproduce_chain_figures(const std::string& plots_dir, bool quick);

}  // namespace pwl::app
