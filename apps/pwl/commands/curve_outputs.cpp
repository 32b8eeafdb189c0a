#include "commands/curve_outputs.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "commands/study_runner.hpp"
#include "output/gnuplot.hpp"
#include "parallel/stop_signals.hpp"

namespace pwl::app {

namespace {

// A number, or an empty field for NaN.
std::string field(double value) { return std::isnan(value) ? std::string() : full_precision(value); }

}  // namespace

void stop_on_signal(const std::string& folder) {
  if (const int signal = StopSignals::received(); signal != 0) {
    throw Stopped(signal, fmt::format("stopped by {}: every row written so far is whole in {}",
                                      signal_name(signal), folder));
  }
}

std::vector<std::string> curve_columns(const orbits::CurvesOptions& options, int dofs) {
  std::vector<std::string> c{"curve", "type", options.first.name(), options.second.name(),
                             "period", "spring", "multiplier_re", "multiplier_im", "kappa"};
  for (int i = 1; i <= dofs; ++i) c.push_back(fmt::format("amplitude_x{}", i));
  for (int i = 1; i <= dofs; ++i) c.push_back(fmt::format("x{}", i));
  for (int i = 1; i <= dofs; ++i) c.push_back(fmt::format("v{}", i));
  return c;
}

std::vector<std::string> codim2_columns(const orbits::CurvesOptions& options) {
  return {"type", options.first.name(), options.second.name(), "curves", "detail"};
}

CurveOutputs::CurveOutputs(const std::string& folder, const orbits::CurvesOptions& options,
                           int dofs, bool progress)
    : options_(options),
      dofs_(dofs),
      curves_(folder + "/curves.csv", curve_columns(options, dofs)),
      codim2_(folder + "/codim2.csv", codim2_columns(options)),
      progress_(progress) {
  folder_ = folder;
}


void CurveOutputs::point(const orbits::CurvePointRecord& p) {
  std::string row = fmt::format("{},{},{},{},{},{},{},{},{}", p.curve,
                                orbits::curve_type_name(p.type), full_precision(p.p),
                                full_precision(p.q), p.period,
                                p.spring >= 0 ? fmt::format("{}", p.spring + 1) : std::string(),
                                field(p.multiplier.real()), field(p.multiplier.imag()),
                                field(p.kappa));
  for (int i = 0; i < dofs_; ++i) row += "," + field(p.amplitude(i));
  for (Index i = 0; i < p.state.size(); ++i) row += "," + full_precision(p.state(i));
  curves_.row(row);
  if (progress_.due(p.curve != last_curve_)) {
    progress_.show(fmt::format("curves: {} points, curve {} ({}), {} = {:.6g}, {} = {:.6g}, {:.1f} s",
                               curves_.rows(), p.curve, orbits::curve_type_name(p.type),
                               options_.first.name(), p.p, options_.second.name(), p.q,
                               progress_.seconds()));
  }
  last_curve_ = p.curve;
  stop_on_signal(folder_);
}

void CurveOutputs::codim2(const orbits::Codim2Point& c) {
  std::vector<std::string> curves;
  for (int id : c.curves) curves.push_back(fmt::format("{}", id));
  codim2_.row(fmt::format("{},{},{},{},{}", c.type, full_precision(c.p), full_precision(c.q),
                          fmt::join(curves, ";"), c.detail));
}

void CurveOutputs::finish_progress() { progress_.finish(); }

void print_curves(const orbits::CurvesResult& result, const orbits::CurvesOptions& options) {
  fmt::print("curves ({}) in ({}, {}):\n", result.curves.size(), options.first.name(),
             options.second.name());
  for (const orbits::CurveSummary& c : result.curves) {
    fmt::print("  curve {}: {}{}, period {}, from {} = {:.10g}, {} = {:.10g}: {} points; "
               "forward: {}; backward: {}\n",
               c.curve, orbits::curve_type_name(c.type),
               c.spring >= 0 ? fmt::format(" of spring {} ({} gap)", c.spring + 1,
                                           c.at_largest_gap ? "largest" : "smallest")
                             : std::string(),
               c.period, options.first.name(), c.start_p, options.second.name(), c.start_q,
               c.points, c.ends[0], c.ends[1]);
  }
  if (result.codim2.empty()) {
    fmt::print("codimension-two points: none found\n");
    return;
  }
  fmt::print("codimension-two points ({}):\n", result.codim2.size());
  for (const orbits::Codim2Point& c : result.codim2) {
    std::vector<std::string> curves;
    for (int id : c.curves) curves.push_back(fmt::format("{}", id));
    fmt::print("  {:<32} {} = {:.10g}, {} = {:.10g} (curve {}){}\n", c.type, options.first.name(),
               c.p, options.second.name(), c.q, fmt::join(curves, ", "),
               c.detail.empty() ? std::string() : ": " + c.detail);
  }
}

void draw_curves(const std::string& folder, const orbits::CurvesOptions& options,
                 const orbits::CurvesResult& result, const std::string& title) {
  if (result.points.empty()) {
    fmt::print(stderr, "pwl continue: no figure of the curves: no curve was followed\n");
    return;
  }
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "curves='{0}/curves.csv'; codim2='{0}/codim2.csv'; ncodim2={5}; "
        "out='{0}/bifurcation_curves.{1}'; xname={2}; yname={3}; title={4}; "
        "xlo={6:.17g}; xhi={7:.17g}; ylo={8:.17g}; yhi={9:.17g}",
        folder, format, gnuplot_quoted(parameter_label(options.first)),
        gnuplot_quoted(parameter_label(options.second)), gnuplot_quoted(title),
        result.codim2.size(), std::min(options.p_from, options.p_to),
        std::max(options.p_from, options.p_to), std::min(options.q_from, options.q_to),
        std::max(options.q_from, options.q_to));
  };
  draw_figure_and_report(scripts_directory() + "/bifurcation_curves.gp", definitions,
                         folder + "/bifurcation_curves", "pwl continue", false);
}

}  // namespace pwl::app
