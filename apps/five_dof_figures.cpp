#include "five_dof_figures.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <vector>

#include "csv_writer.hpp"
#include "gnuplot.hpp"
#include "pwl/chain_builders.hpp"
#include "pwl/pim_integrator.hpp"
#include "pwl/reference_integrator.hpp"

namespace pwl::app {

int count_distinct_points(const std::vector<std::pair<double, double>>& points, double tolerance) {
  if (points.empty()) return 0;
  double lo_x = points[0].first, hi_x = lo_x, lo_v = points[0].second, hi_v = lo_v;
  for (auto [x, v] : points) {
    lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x);
    lo_v = std::min(lo_v, v), hi_v = std::max(hi_v, v);
  }
  const double radius = tolerance * std::max(1.0, std::hypot(hi_x - lo_x, hi_v - lo_v));
  std::vector<std::pair<double, double>> centres;
  for (auto p : points) {
    bool seen = false;
    for (auto c : centres) {
      if (std::hypot(p.first - c.first, p.second - c.second) <= radius) {
        seen = true;
        break;
      }
    }
    if (!seen) centres.push_back(p);
  }
  return static_cast<int>(centres.size());
}

FiveDofFigureResult reproduce_five_dof_figure(const std::string& figure,
                                              const std::string& plots_dir, bool quick) {
  const NondimensionalChain chain = paper_five_dof_case(figure);
  const GapStructure structure = make_chain(chain);
  const double period = chain.period();
  const int periods = quick ? 300 : 1000, kept_from = quick ? 200 : 500, steps = 200;
  const int drawn_periods = 20;  // of trajectory in the phase portrait
  const double eta = period / steps;

  PimOptions pim_options;
  pim_options.step = eta;
  auto pim = make_pim_integrator(structure, pim_options);
  ReferenceOptions ref_options;
  ref_options.relative_tolerance = ref_options.absolute_tolerance = 1e-10;
  ref_options.locate_kinks = true;
  auto reference = make_reference_integrator(structure, ref_options);
  const Vector rest = Vector::Zero(structure.dofs());
  pim->set_state(0.0, rest, rest);
  reference->set_state(0.0, rest, rest);

  const std::string data = plots_dir + "/data";
  std::filesystem::create_directories(data);
  FiveDofFigureResult result;
  result.figure = figure;
  std::vector<std::pair<double, double>> pim_points, ref_points;
  {  // the CSV files close at the end of this block, before gnuplot reads them
    CsvWriter pim_csv(fmt::format("{}/fig{}_pim.csv", data, figure), {"t", "x5", "v5"});
    CsvWriter ref_csv(fmt::format("{}/fig{}_reference.csv", data, figure), {"t", "x5", "v5"});
    CsvWriter strobe(fmt::format("{}/fig{}_poincare.csv", data, figure),
                     {"t", "x5_pim", "v5_pim", "x5_reference", "v5_reference"});

    using Clock = std::chrono::steady_clock;
    double pim_time = 0.0, ref_time = 0.0;
    // Both integrators land on every PIM step so that the trajectories compare point by point.
    for (long k = 1; k <= static_cast<long>(periods) * steps; ++k) {
      const double t = static_cast<double>(k) * eta;
      auto t0 = Clock::now();
      pim->advance_to(t);
      auto t1 = Clock::now();
      reference->advance_to(t);
      auto t2 = Clock::now();
      pim_time += std::chrono::duration<double>(t1 - t0).count();
      ref_time += std::chrono::duration<double>(t2 - t1).count();
      const double diff = std::max((pim->position() - reference->position()).cwiseAbs().maxCoeff(),
                                   (pim->velocity() - reference->velocity()).cwiseAbs().maxCoeff());
      result.largest_difference = std::max(result.largest_difference, diff);
      if (k <= static_cast<long>(kept_from) * steps) continue;
      // The phase portrait draws the last periods; the Poincaré points cover all kept ones.
      if (k > static_cast<long>(periods - drawn_periods) * steps) {
        pim_csv.row({t, pim->position()[4], pim->velocity()[4]});
        ref_csv.row({t, reference->position()[4], reference->velocity()[4]});
      }
      if (k % steps == 0) {
        strobe.row({t, pim->position()[4], pim->velocity()[4], reference->position()[4],
                    reference->velocity()[4]});
        pim_points.emplace_back(pim->position()[4], pim->velocity()[4]);
        ref_points.emplace_back(reference->position()[4], reference->velocity()[4]);
        result.largest_poincare_difference = std::max(result.largest_poincare_difference, diff);
      }
    }
    result.pim_seconds = pim_time;
    result.reference_seconds = ref_time;
  }
  result.distinct_points = count_distinct_points(pim_points, 1e-4);
  result.reference_distinct_points = count_distinct_points(ref_points, 1e-4);
  double lo_x = 1e300, hi_x = -1e300, lo_v = 1e300, hi_v = -1e300;
  for (auto [x, v] : pim_points) {
    lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x);
    lo_v = std::min(lo_v, v), hi_v = std::max(hi_v, v);
  }
  result.attractor_size = std::hypot(hi_x - lo_x, hi_v - lo_v);

  std::string why;
  for (const char* format : {"png", "svg"}) {
    const std::string definitions = fmt::format(
        "data='{}'; fig='{}'; out='{}/fig{}.{}'; fmt='{}'; "
        "params='α = {}, ζ = {}, Δ̃ = {}, θ = {}; η = T/200; periods {}-{}'; "
        "points={}; diff='{:.1e}'",
        data, figure, plots_dir, figure, format, format, chain.alpha[0], chain.zeta, chain.gap[0],
        chain.theta, kept_from, periods, result.distinct_points, result.largest_difference);
    if (!run_gnuplot(plots_directory() + "/five_dof_phase.gp", definitions, &why)) {
      fmt::print(stderr, "pwl reproduce: no figure {}: {}\n", figure, why);
      break;
    }
  }
  return result;
}

}  // namespace pwl::app
