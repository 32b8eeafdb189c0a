#include "bench/chain_figures.hpp"

#include <fmt/format.h>

#include <tuple>

#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {

bool draw_chain_figures(const ChainBenchResult& r, const std::string& dir, std::string* why) {
  const ChainMethodResult* pim = nullptr;
  const ChainMethodResult* rk = nullptr;
  for (const ChainMethodResult& m : r.methods) {
    if (m.base) pim = &m;
    if (m.key == "dopri5-1e-5") rk = &m;
  }
  if (pim == nullptr || rk == nullptr) {
    throw InputError("--figures: figures 7-9 need the methods pim-banded and dopri5-1e-5");
  }
  const ChainBenchOptions& o = r.options;
  const std::string phase = dir + "/fig7_phase_mass1.csv";
  const std::string pim_errors = dir + "/fig8_errors_banded_pim.csv";
  const std::string rk_errors = dir + "/fig9_errors_dopri5.csv";
  {  // closed before gnuplot reads them
    CsvWriter csv(phase, {"t", "x1", "v1"});
    for (std::size_t i = 0; i < pim->record.t.size(); ++i) {
      if (pim->record.t[i] >= o.t_end / 2)
        csv.row({pim->record.t[i], pim->record.x[i], pim->record.v[i]});
    }
    for (auto [path, m] : {std::pair{pim_errors, pim}, std::pair{rk_errors, rk}}) {
      CsvWriter e(path, {"t", "error_x1", "error_v1"});
      for (std::size_t i = 0; i < m->record.t.size(); ++i) {
        const double t = m->record.t[i];
        e.row({t, m->record.x[i] - r.reference.position(t),
               m->record.v[i] - r.reference.velocity(t)});
      }
    }
  }
  const std::string chain = fmt::format(
      "n = {}, m = 1 kg, k_1 = k_2 = 1 N/m, c = 0.2 N·s/m, Δ = 0; sin 3t N on odd, -2 sin 5t N on "
      "even masses",
      o.masses);
  const std::string reference = fmt::format("rkf78 kink-located, tol {:g}", o.reference_tolerance);
  const std::string pim_label = fmt::format("banded PIM, η = {:g} s", o.paper_step);
  const auto phase_definitions = [&](const std::string& format) {
    return fmt::format("data='{}'; out='{}/fig7.{}'; params={}; method={}; t_from={:g}; t_to={:g}",
                       phase, dir, format, gnuplot_quoted(chain), gnuplot_quoted(pim_label),
                       o.t_end / 2, o.t_end);
  };
  if (!draw_figure(scripts_directory() + "/fig7_phase_mass1.gp", phase_definitions, why))
    return false;
  for (auto [fig, path, m, label] :
       {std::tuple{8, pim_errors, pim, pim_label},
        std::tuple{9, rk_errors, rk,
                   std::string("dopri5, rtol = atol = 1e-5 (plain, like ode45)")}}) {
    const auto definitions = [&](const std::string& format) {
      return fmt::format(
          "data='{}'; out='{}/fig{}.{}'; fig={}; method={}; params={}; reference={}; ex='{:.1e}'; "
          "ev='{:.1e}'",
          path, dir, fig, format, fig, gnuplot_quoted(label), gnuplot_quoted(chain),
          gnuplot_quoted(reference), m->error_x, m->error_v);
    };
    if (!draw_figure(scripts_directory() + "/fig8_9_errors.gp", definitions, why)) return false;
  }
  return true;
}

}  // namespace pwl::app
