#include "pwl/study/basin_map.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pwl/errors.hpp"
#include "pwl/study/indicators.hpp"
#include "pwl/study/parameter_sweep.hpp"

namespace pwl::analysis {

double StateAxis::value(int index) const { return grid_value(from, to, points, index); }

BasinMapOptions::BasinMapOptions() { point.kept_points = 64; }

PointModel BasinMapOptions::model() const {
  return structure ? PointModel(*structure) : PointModel(chain);
}

bool BasinMapOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  const PointModel m = model();
  const int size = 2 * m.dofs();
  for (const StateAxis* axis : {&first, &second}) {
    const char* which = axis == &first ? "first" : "second";
    if (axis->component < 0 || axis->component >= size) {
      *why = fmt::format("{} axis: component {} is out of range: the state has {} components "
                         "(0..{})",
                         which, axis->component, size, size - 1);
      return false;
    }
    if (axis->points < 1) {
      *why = fmt::format("{} axis: points = {} must be at least 1", which, axis->points);
      return false;
    }
    if (!std::isfinite(axis->from) || !std::isfinite(axis->to) ||
        (axis->points > 1 && !(axis->from < axis->to))) {
      *why = fmt::format("{} axis: range [{}, {}] must be finite with from < to", which,
                         axis->from, axis->to);
      return false;
    }
  }
  if (first.component == second.component) {
    *why = fmt::format("both axes vary {}: give two different state components",
                       component_name(first.component, m.dofs()));
    return false;
  }
  if (base_state.size() != 0 && (base_state.size() != size || !base_state.allFinite())) {
    *why = fmt::format("base state has {} entries (finite: {}), expected {} finite ones",
                       base_state.size(), base_state.allFinite(), size);
    return false;
  }
  if (!point.section.stroboscopic() || point.section.phase != 0.0) {
    *why = "section: a basin map matches attractors on the stroboscopic points at phase 0, where "
           "every cell starts; give the strobe at phase 0";
    return false;
  }
  if (point.kept_points < 2) {
    *why = fmt::format("kept points = {} must be at least 2: the attractors are matched on the "
                       "last points of each motion",
                       point.kept_points);
    return false;
  }
  if (point.kept_points > point.recorded_periods) {
    *why = fmt::format("kept points = {} exceeds the recorded periods ({})", point.kept_points,
                       point.recorded_periods);
    return false;
  }
  if (!settings().is_valid(m.dofs(), why)) return false;
  if (!matching.is_valid(why)) return false;
  std::string reason;
  PointCase base = [&] {
    try {
      return m.point_case();
    } catch (const InputError& e) {
      reason = e.what();
      return PointCase(NondimensionalChain{});
    }
  }();
  if (!reason.empty()) {
    *why = reason;
    return false;
  }
  if (!point.method_for(base.period).is_valid(base.structure, &reason)) {
    *why = fmt::format("method {}: {}", method_label(point.method), reason);
    return false;
  }
  return true;
}

PointSettings BasinMapOptions::settings() const {
  PointSettings s = point;
  s.components.clear();
  for (int c = 0; c < 2 * model().dofs(); ++c) s.components.push_back(c);
  return s;
}

Vector BasinMapOptions::initial_state(long id) const {
  const int i = static_cast<int>(id % first.points);
  const int j = static_cast<int>(id / first.points);
  Vector state = base_state.size() != 0 ? base_state : Vector::Zero(2 * model().dofs());
  state[first.component] = first.value(i);
  state[second.component] = second.value(j);
  return state;
}

std::vector<GridTask> BasinMapOptions::tasks() const {
  std::vector<GridTask> result;
  result.reserve(static_cast<std::size_t>(cells()));
  for (long id = 0; id < cells(); ++id) result.push_back({{id}, false, initial_state(id)});
  return result;
}

PointCase BasinMapOptions::case_of(long /*id*/) const { return model().point_case(); }

std::string BasinMapOptions::describe() const {
  const int dofs = model().dofs();
  std::string s = "study = basin\n";
  s += model().describe();
  for (const StateAxis* axis : {&first, &second}) {
    s += fmt::format("{0}_component = {1}\n{0}_from = {2:.17g}\n{0}_to = {3:.17g}\n"
                     "{0}_points = {4}\n",
                     axis == &first ? "first" : "second", component_name(axis->component, dofs),
                     axis->from, axis->to, axis->points);
  }
  const Vector base = base_state.size() != 0 ? base_state : Vector::Zero(2 * dofs);
  s += "base_state = ";
  for (Index i = 0; i < base.size(); ++i) s += fmt::format("{}{:.17g}", i ? "," : "", base[i]);
  s += "\n";
  s += fmt::format("periodic_tolerance = {:.17g}\ncloud_factor = {:.17g}\n",
                   matching.periodic_tolerance, matching.cloud_factor);
  s += settings().describe();
  return s;
}

BasinMap match_basins(const BasinMapOptions& o, const std::map<long, PointResult>& records) {
  AttractorCatalogue catalogue(o.matching);
  BasinMap result;
  for (const auto& [id, r] : records) {
    MotionTail tail;
    tail.regime = r.regime;
    tail.period = r.period;
    const int rows = r.rows();
    tail.points.resize(rows, r.columns);
    for (int k = 0; k < rows; ++k) {
      for (int c = 0; c < r.columns; ++c) {
        tail.points(k, c) = r.poincare[static_cast<std::size_t>(k) * r.columns + c];
      }
    }
    result.attractor_of[id] = catalogue.match(tail, id);
  }
  result.attractors = catalogue.attractors();
  return result;
}

void write_basin_files(const BasinMapOptions& o, const std::map<long, PointResult>& records,
                       const BasinMap& basins, const std::string& folder) {
  const int dofs = o.model().dofs();
  const std::string basin_path = folder + "/basin.csv";
  std::FILE* f = std::fopen(basin_path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}", basin_path));
  fmt::print(f, "i,j,{},{},attractor,{}\n", component_name(o.first.component, dofs),
             component_name(o.second.component, dofs), indicator_header());
  for (const auto& [id, r] : records) {
    const int i = static_cast<int>(id % o.first.points);
    const int j = static_cast<int>(id / o.first.points);
    fmt::print(f, "{},{},{:.17g},{:.17g},{},{}\n", i, j, o.first.value(i), o.second.value(j),
               basins.attractor_of.at(id), indicator_cells(r));
  }
  if (std::fclose(f) != 0) throw Error(fmt::format("cannot finish writing {}", basin_path));

  const std::string attractors_path = folder + "/attractors.csv";
  f = std::fopen(attractors_path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}", attractors_path));
  fmt::print(f, "attractor,regime,period,cells,fraction,first_i,first_j");
  for (int c = 0; c < 2 * dofs; ++c) fmt::print(f, ",{}", component_name(c, dofs));
  fmt::print(f, "\n");
  const double total = static_cast<double>(records.size());
  for (const Attractor& a : basins.attractors) {
    fmt::print(f, "{},{},{},{},{:.6f},{},{}", a.id, a.regime, a.period, a.motions,
               static_cast<double>(a.motions) / total, a.first % o.first.points,
               a.first / o.first.points);
    for (int c = 0; c < 2 * dofs; ++c) {
      if (a.points.rows() > 0) {
        fmt::print(f, ",{:.17g}", a.points(a.points.rows() - 1, c));
      } else {
        fmt::print(f, ",");
      }
    }
    fmt::print(f, "\n");
  }
  if (std::fclose(f) != 0) throw Error(fmt::format("cannot finish writing {}", attractors_path));

  const std::string points_path = folder + "/attractor_points.csv";
  f = std::fopen(points_path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}", points_path));
  fmt::print(f, "attractor");
  for (int c = 0; c < 2 * dofs; ++c) fmt::print(f, ",{}", component_name(c, dofs));
  fmt::print(f, "\n");
  for (const Attractor& a : basins.attractors) {
    const Index rows = a.period > 0 ? std::min<Index>(a.period, a.points.rows()) : a.points.rows();
    for (Index k = a.points.rows() - rows; k < a.points.rows(); ++k) {
      fmt::print(f, "{}", a.id);
      for (int c = 0; c < 2 * dofs; ++c) fmt::print(f, ",{:.17g}", a.points(k, c));
      fmt::print(f, "\n");
    }
  }
  if (std::fclose(f) != 0) throw Error(fmt::format("cannot finish writing {}", points_path));
}

}  // namespace pwl::analysis
