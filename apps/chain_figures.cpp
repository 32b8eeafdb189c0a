#include "chain_figures.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>

#include "bench_chain.hpp"
#include "csv_writer.hpp"
#include "gnuplot.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {

ChainFigureSummary reproduce_chain_figures(const std::string& plots_dir, bool quick) {
  ChainBenchOptions o;
  o.masses = quick ? 200 : 1000;
  o.t_end = 200.0;
  o.runs = 1;
  o.methods = {"pim-banded", "dopri5-1e-5"};
  o.reference_tolerance = quick ? 1e-10 : 1e-12;
  o.reference_grid = quick ? 0.01 : 0.005;
  o.reference_check = false;
  o.out = plots_dir + "/data";
  std::filesystem::create_directories(o.out);
  fmt::print("figures 7-9: the {}-mass chain by the banded PIM and dopri5 ...\n", o.masses);
  std::fflush(stdout);
  const ChainBenchResult r = run_chain_bench(o);
  const ChainMethodResult* pim = nullptr;
  const ChainMethodResult* rk = nullptr;
  for (const ChainMethodResult& m : r.methods) {
    if (m.key == "pim-banded") pim = &m;
    if (m.key == "dopri5-1e-5") rk = &m;
  }
  if (pim == nullptr || rk == nullptr) throw Error("figures 7-9: the chain bench returned no runs");
  ChainFigureSummary summary{o.masses, pim->error_x, pim->error_v, rk->error_x, rk->error_v, false};

  const std::string phase = o.out + "/fig7_phase_mass1.csv";
  const std::string pim_errors = o.out + "/fig8_errors_banded_pim.csv";
  const std::string rk_errors = o.out + "/fig9_errors_dopri5.csv";
  {  // closed before gnuplot reads them
    CsvWriter csv(phase, {"t", "x1", "v1"});
    for (std::size_t i = 0; i < pim->record.t.size(); ++i) {
      if (pim->record.t[i] >= 100.0)
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
      "even masses{}",
      o.masses, quick ? " (quick run)" : "");
  const std::string reference = fmt::format("rkf78 kink-located, tol {:g}", o.reference_tolerance);
  std::string why;
  const std::string dir = plots_directory();
  bool ok = run_gnuplot(dir + "/fig7_phase_mass1.gp",
                        fmt::format("data='{}'; out='{}/fig7.png'; params='{}'; method='{}'", phase,
                                    plots_dir, chain, "banded PIM, η = 0.02 s"),
                        &why);
  for (auto [fig, path, m, label] :
       {std::tuple{8, pim_errors, pim, std::string("banded PIM, η = 0.02 s")},
        std::tuple{9, rk_errors, rk,
                   std::string("dopri5, rtol = atol = 1e-5 (plain, like ode45)")}}) {
    if (!ok) break;
    ok = run_gnuplot(
        dir + "/fig8_9_errors.gp",
        fmt::format("data='{}'; out='{}/fig{}.png'; fig={}; method='{}'; params='{}'; "
                    "reference='{}'; ex='{:.1e}'; ev='{:.1e}'",
                    path, plots_dir, fig, fig, label, chain, reference, m->error_x, m->error_v),
        &why);
  }
  if (!ok) {
    fmt::print(stderr, "pwl reproduce: figures 7-9 not drawn: {}\n", why);
  } else {
    fmt::print("figures 7-9: {0}/fig7.png, {0}/fig8.png, {0}/fig9.png\n", plots_dir);
  }
  summary.drawn = ok;
  fmt::print(
      "  largest error of x1: banded PIM {:.2e} m, dopri5 1e-5 {:.2e} m (ratio {:.1f}); "
      "of x1': {:.2e} and {:.2e} m/s (ratio {:.1f})\n",
      pim->error_x, rk->error_x, rk->error_x / pim->error_x, pim->error_v, rk->error_v,
      rk->error_v / pim->error_v);
  return summary;
}

}  // namespace pwl::app
