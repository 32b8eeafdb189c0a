#include "commands/method_comparison.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {

double cloud_diameter(const std::vector<std::pair<double, double>>& points) {
  if (points.empty()) return 0.0;
  double lo_x = points[0].first, hi_x = lo_x, lo_v = points[0].second, hi_v = lo_v;
  for (auto [x, v] : points) {
    lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x);
    lo_v = std::min(lo_v, v), hi_v = std::max(hi_v, v);
  }
  return std::hypot(hi_x - lo_x, hi_v - lo_v);
}

int count_distinct_points(const std::vector<std::pair<double, double>>& points, double tolerance) {
  if (points.empty()) return 0;
  const double radius = tolerance * std::max(1.0, cloud_diameter(points));
  std::vector<std::pair<double, double>> centres;
  for (auto p : points) {
    const bool seen = std::any_of(centres.begin(), centres.end(), [&](auto c) {
      return std::hypot(p.first - c.first, p.second - c.second) <= radius;
    });
    if (!seen) centres.push_back(p);
  }
  return static_cast<int>(centres.size());
}

ComparisonResult simulate_with_comparison(const CaseOptions& run, const ComparisonOptions& with,
                                          const RecordingOptions& output) {
  const std::vector<int>& record = output.record;
  const std::string& out = output.out;
  if (record.empty()) throw InputError("--compare-with needs --record MASS (the mass to draw)");
  const GapStructure structure = run.structure();
  const Index n = structure.dofs();
  const double period = run.period();
  CaseOptions other = run;
  other.method = with.method;
  other.tolerance = with.tolerance;
  other.locate_kinks = with.locate_kinks;
  other.force_degree = -1;  // --force-degree is the first method's (the other takes its default)
  auto a = run.integrator(structure, period);
  auto b = other.integrator(structure, period);
  // Both land on the first method's grid (its step, or T / steps-per-period for Runge-Kutta).
  const long steps = std::lround(period / run.step(period));
  const double eta = period / static_cast<double>(steps);
  std::filesystem::create_directories(out);

  std::vector<std::string> columns{"t"};
  for (int r : record) columns.push_back(fmt::format("x{}", r));
  for (int r : record) columns.push_back(fmt::format("v{}", r));
  ComparisonResult result;
  std::vector<std::pair<double, double>> points_a, points_b;
  const int mass = record.front();
  {  // the files close at the end of this block, before gnuplot reads them
    CsvWriter poincare_a(out + "/poincare.csv", state_columns("t", n));
    CsvWriter poincare_b(out + "/reference_poincare.csv", state_columns("t", n));
    CsvWriter trajectory_a(out + "/trajectory.csv", columns);
    CsvWriter trajectory_b(out + "/reference_trajectory.csv", columns);
    std::vector<double> row(columns.size());
    const auto write = [&](CsvWriter& csv, const Integrator& i) {
      row[0] = i.time();
      for (std::size_t j = 0; j < record.size(); ++j) {
        row[1 + j] = i.position()[record[j] - 1];
        row[1 + record.size() + j] = i.velocity()[record[j] - 1];
      }
      csv.row(row);
    };
    const int drawn_from = output.trajectory_periods > 0
                               ? std::max(run.skip_periods, run.periods - output.trajectory_periods)
                               : run.skip_periods;
    if (run.skip_periods == 0) {  // as plain `pwl simulate`: the start is a Poincaré point
      poincare_a.row(a->time(), a->position(), a->velocity());
      poincare_b.row(b->time(), b->position(), b->velocity());
    }
    for (int k = 1; k <= run.periods; ++k) {
      const bool keep = k > run.skip_periods;
      for (long j = 1; j <= steps; ++j) {
        const double t =
            (static_cast<double>(k - 1) * static_cast<double>(steps) + static_cast<double>(j)) *
            eta;
        a->advance_to(j == steps ? k * period : t);
        b->advance_to(a->time());
        const double difference = std::max((a->position() - b->position()).cwiseAbs().maxCoeff(),
                                           (a->velocity() - b->velocity()).cwiseAbs().maxCoeff());
        result.largest_difference = std::max(result.largest_difference, difference);
        if (k > drawn_from) write(trajectory_a, *a), write(trajectory_b, *b);
        if (j == steps && keep) {
          result.largest_poincare_difference =
              std::max(result.largest_poincare_difference, difference);
          poincare_a.row(a->time(), a->position(), a->velocity());
          poincare_b.row(b->time(), b->position(), b->velocity());
          points_a.emplace_back(a->position()[mass - 1], a->velocity()[mass - 1]);
          points_b.emplace_back(b->position()[mass - 1], b->velocity()[mass - 1]);
        }
      }
    }
  }
  result.distinct_points = count_distinct_points(points_a, 1e-4);
  result.reference_distinct_points = count_distinct_points(points_b, 1e-4);
  result.cloud_size = cloud_diameter(points_a);

  const std::string label_a = method_label(run.method_settings(period));
  const std::string label_b = method_label(other.method_settings(period));
  if (!output.quiet) {
    fmt::print("{} against {}, on a grid of T/{}:\n", label_a, label_b, steps);
    fmt::print("largest difference (every x and x', every step): {:.2e}\n",
               result.largest_difference);
    fmt::print("largest difference at the Poincaré points: {:.2e}\n",
               result.largest_poincare_difference);
    fmt::print("distinct Poincaré points of mass {}: {} ({}: {}); cloud size {:.3g}\n", mass,
               result.distinct_points, label_b, result.reference_distinct_points,
               result.cloud_size);
  }
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "out='{0}/comparison.{1}'; trajectory='{0}/trajectory.csv'; "
        "reference_trajectory='{0}/reference_trajectory.csv'; poincare='{0}/poincare.csv'; "
        "reference_poincare='{0}/reference_poincare.csv'; xcol=2; vcol={2}; pxcol={3}; "
        "pvcol={4}; mass={5}; method='{6}'; reference='{7}'; title={8}; subtitle='{9}; "
        "η = T/{10}; periods {11}-{12}; {13} distinct Poincaré points; largest difference "
        "{14:.1e}'",
        out, format, 2 + record.size(), 1 + mass, 1 + n + mass, mass, label_a, label_b,
        gnuplot_quoted(output.title.empty()
                           ? fmt::format("Mass {}: {} against {}", mass, label_a, label_b)
                           : output.title),
        run.description(), steps, run.skip_periods, run.periods, result.distinct_points,
        result.largest_difference);
  };
  draw_figure_and_report(scripts_directory() + "/comparison.gp", definitions,
                         out + "/comparison", "pwl simulate", output.quiet);
  return result;
}

}  // namespace pwl::app
