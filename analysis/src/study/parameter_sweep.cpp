#include "pwl/study/parameter_sweep.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "pwl/errors.hpp"
#include "pwl/study/indicators.hpp"

namespace pwl::analysis {


std::string component_name(int component, int masses) {
  return component < masses ? fmt::format("x{}", component + 1)
                            : fmt::format("v{}", component - masses + 1);
}

PointModel SweepOptions::model() const {
  return structure ? PointModel(*structure) : PointModel(chain);
}

bool SweepOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (points < 1) {
    *why = fmt::format("points = {} must be at least 1", points);
    return false;
  }
  if (!std::isfinite(from) || !std::isfinite(to)) {
    *why = fmt::format("range [{}, {}] must be finite", from, to);
    return false;
  }
  if (points > 1 && !(from < to)) {
    *why = fmt::format("range [{}, {}] is reversed or empty: give from < to (a continuation runs "
                       "both directions by itself)",
                       from, to);
    return false;
  }
  if (mode == SweepMode::continuation && !upward && !downward) {
    *why = "a continuation needs the upward or the downward branch (or both)";
    return false;
  }
  const PointModel m = model();
  if (!point.is_valid(m.dofs(), why)) return false;
  if (initial_state.size() != 0 && initial_state.size() != 2 * m.dofs()) {
    *why = fmt::format("initial state has {} entries, expected {}", initial_state.size(),
                       2 * m.dofs());
    return false;
  }
  // Every value must give a valid case (θ > 0, α >= 0, a gap spring's stiffness >= 0, loads with a
  // common period, ...). The chain's checks are cheap but its range is monotone in each parameter,
  // so its two ends decide; an explicit structure's loads may lose their common period anywhere
  // in between, so every value is checked.
  if (!m.has(parameter, why)) return false;
  std::vector<double> checked{from, to};
  if (m.explicit_structure()) {
    for (int i = 1; i + 1 < points; ++i) checked.push_back(value(i));
  }
  for (double v : checked) {
    if (!m.accepts(parameter, v, why)) return false;
  }
  std::string reason;
  const PointCase base = m.with(parameter, from).point_case();
  if (!point.method_for(base.period).is_valid(base.structure, &reason)) {
    *why = fmt::format("method {}: {}", method_label(point.method), reason);
    return false;
  }
  return true;
}

double SweepOptions::value(int index) const { return grid_value(from, to, points, index); }

std::vector<GridTask> SweepOptions::tasks() const {
  std::vector<GridTask> result;
  if (mode == SweepMode::independent) {
    for (int i = 0; i < points; ++i) result.push_back({{i}, false, {}});
    return result;
  }
  if (upward) {
    GridTask up{{}, true, {}};
    for (int i = 0; i < points; ++i) up.ids.push_back(i);
    result.push_back(std::move(up));
  }
  if (downward) {
    GridTask down{{}, true, {}};
    for (int i = points - 1; i >= 0; --i) down.ids.push_back(points + i);
    result.push_back(std::move(down));
  }
  return result;
}

PointCase SweepOptions::case_of(long id) const {
  return model().with(parameter, value(static_cast<int>(id % points))).point_case();
}

NondimensionalChain SweepOptions::chain_of(long id) const {
  if (structure) throw InputError("a sweep of an explicit structure has no chain");
  return with_parameter(chain, parameter, value(static_cast<int>(id % points)));
}

Vector SweepOptions::start_state() const {
  return initial_state.size() != 0 ? initial_state : Vector::Zero(2 * model().dofs());
}

std::string SweepOptions::describe() const {
  std::string s;
  s += "study = sweep\n";
  s += model().describe();
  s += fmt::format("parameter = {}\nfrom = {:.17g}\nto = {:.17g}\npoints = {}\n",
                   parameter_name(parameter), from, to, points);
  s += fmt::format("mode = {}\n", mode == SweepMode::independent ? "independent" : "continuation");
  if (mode == SweepMode::continuation) {
    s += fmt::format("upward = {}\ndownward = {}\n", upward, downward);
  }
  const Vector start = start_state();
  s += "initial_state = ";
  for (Index i = 0; i < start.size(); ++i) s += fmt::format("{}{:.17g}", i ? "," : "", start[i]);
  s += "\n";
  s += point.describe();
  return s;
}

void write_sweep_files(const SweepOptions& o, const std::map<long, PointResult>& records,
                       const std::string& folder) {
  const std::string poincare_path = folder + "/poincare.csv";
  const std::string classes_path = folder + "/classification.csv";
  std::FILE* poincare = std::fopen(poincare_path.c_str(), "w");
  std::FILE* classes = std::fopen(classes_path.c_str(), "w");
  if (poincare == nullptr || classes == nullptr) {
    if (poincare) std::fclose(poincare);
    if (classes) std::fclose(classes);
    throw Error(fmt::format("cannot write {} and {}", poincare_path, classes_path));
  }
  const std::string name = parameter_name(o.parameter);
  const int dofs = o.model().dofs();
  // A stroboscopic point is numbered by its period; a hyperplane's crossing by its time.
  const bool crossings = !o.point.section.stroboscopic();
  fmt::print(poincare, "{},direction,index,{}", name, crossings ? "t" : "period_index");
  for (int c : o.point.components) fmt::print(poincare, ",{}", component_name(c, dofs));
  fmt::print(poincare, "\n");
  fmt::print(classes, "index,{},direction,{}\n", name, indicator_header());
  // std::map iterates in id order: up (0..N-1) then down (N..2N-1), each by index.
  for (const auto& [id, r] : records) {
    const int index = static_cast<int>(id % o.points);
    const char* direction = id < o.points ? "up" : "down";
    const double value = o.value(index);
    fmt::print(classes, "{},{:.17g},{},{}\n", index, value, direction, indicator_cells(r));
    const int rows = r.rows();
    for (int k = 0; k < rows; ++k) {
      if (crossings) {
        fmt::print(poincare, "{:.17g},{},{},{:.17g}", value, direction, index,
                   static_cast<std::size_t>(k) < r.section_times.size()
                       ? r.section_times[static_cast<std::size_t>(k)]
                       : std::numeric_limits<double>::quiet_NaN());
      } else {
        fmt::print(poincare, "{:.17g},{},{},{}", value, direction, index,
                   o.point.transient_periods + k + 1);
      }
      for (int c = 0; c < r.columns; ++c) {
        fmt::print(poincare, ",{:.17g}",
                   r.poincare[static_cast<std::size_t>(k) * static_cast<std::size_t>(r.columns) +
                              static_cast<std::size_t>(c)]);
      }
      fmt::print(poincare, "\n");
    }
  }
  const bool ok = std::fclose(poincare) == 0;
  if (std::fclose(classes) != 0 || !ok) {
    throw Error(fmt::format("cannot finish writing {} and {}", poincare_path, classes_path));
  }
}

}  // namespace pwl::analysis
