#pragma once
// The paper's figures 7-9 (He, Gao & Zhong 2018, section 4.2; SPEC.md §5) for its chain, drawn
// from a run of `pwl bench chain --figures`:
//   fig7.png  phase portrait of mass 1 for t in [t_end / 2, t_end], by the banded PIM
//   fig8.png  error of x1 and x1' of the banded PIM against the reference
//   fig9.png  the same for dopri5 at tolerance 1e-5 (plain, like the paper's ode45)
// each also as SVG. The reference is the benchmark's kink-located rkf78 (tolerance 1e-12 by
// default), where the paper used ode45 at 1e-10.
#include <string>

#include "bench/bench_chain.hpp"

namespace pwl::app {

// Writes what the figures plot as CSV into `dir` and draws them there. Throws InputError when
// the run lacks the banded PIM (pim-banded) or dopri5 at 1e-5 (dopri5-1e-5); returns false and
// fills *why when gnuplot could not draw.
bool draw_chain_figures(const ChainBenchResult& result, const std::string& dir, std::string* why);

}  // namespace pwl::app
