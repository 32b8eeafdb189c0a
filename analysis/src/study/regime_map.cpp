#include "pwl/study/regime_map.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "pwl/errors.hpp"
#include "pwl/study/indicators.hpp"

namespace pwl::analysis {

double MapAxis::value(int index) const { return grid_value(from, to, points, index); }

namespace {

SweepOptions as_sweep(const PointModel& model, const MapAxis& axis, const PointSettings& point,
                      const Vector& initial_state) {
  SweepOptions s;
  if (model.explicit_structure()) {
    s.structure = model.structure();
  } else {
    s.chain = model.chain();
  }
  s.parameter = axis.parameter;
  s.from = axis.from;
  s.to = axis.to;
  s.points = axis.points;
  s.point = point;
  s.point.components.clear();
  s.initial_state = initial_state;
  return s;
}

}  // namespace

PointModel RegimeMapOptions::model() const {
  return structure ? PointModel(*structure) : PointModel(chain);
}

bool RegimeMapOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!point.section.stroboscopic()) {
    *why = "section: a regime map keeps no Poincaré points, only each cell's indicators, which are "
           "classified on the stroboscopic map whatever the section; give the strobe (at any "
           "phase)";
    return false;
  }
  if (first.parameter == second.parameter) {
    *why = fmt::format("both axes vary {}: give two different parameters",
                       parameter_name(first.parameter));
    return false;
  }
  const PointModel base = model();
  for (const MapAxis* axis : {&first, &second}) {
    // Each axis alone, at the other axis's ends.
    const MapAxis& other = axis == &first ? second : first;
    if (!base.has(other.parameter, why)) return false;
    for (double v : {other.from, other.to}) {
      const SweepOptions s = as_sweep(base.with(other.parameter, v), *axis, point, initial_state);
      std::string reason;
      if (!s.is_valid(&reason)) {
        *why = fmt::format("{} axis: {}", axis == &first ? "first" : "second", reason);
        return false;
      }
    }
  }
  return true;
}

std::vector<GridTask> RegimeMapOptions::tasks() const {
  std::vector<GridTask> result;
  if (mode == SweepMode::independent) {
    for (long id = 0; id < cells(); ++id) result.push_back({{id}, false, {}});
    return result;
  }
  for (int j = 0; j < second.points; ++j) {
    GridTask row{{}, true, {}};
    for (int i = 0; i < first.points; ++i) row.ids.push_back(i + static_cast<long>(first.points) * j);
    result.push_back(std::move(row));
  }
  return result;
}

PointCase RegimeMapOptions::case_of(long id) const {
  const int i = static_cast<int>(id % first.points);
  const int j = static_cast<int>(id / first.points);
  return model()
      .with(second.parameter, second.value(j))
      .with(first.parameter, first.value(i))
      .point_case();
}

NondimensionalChain RegimeMapOptions::chain_of(long id) const {
  if (structure) throw InputError("a map of an explicit structure has no chain");
  const int i = static_cast<int>(id % first.points);
  const int j = static_cast<int>(id / first.points);
  return with_parameter(with_parameter(chain, second.parameter, second.value(j)), first.parameter,
                        first.value(i));
}

Vector RegimeMapOptions::start_state() const {
  return initial_state.size() != 0 ? initial_state : Vector::Zero(2 * model().dofs());
}

std::string RegimeMapOptions::describe() const {
  SweepOptions s = as_sweep(model(), first, point, initial_state);
  s.mode = mode;
  s.upward = true;
  s.downward = false;
  std::string text = s.describe();
  text.replace(0, text.find('\n'), "study = map");
  text += fmt::format("second_parameter = {}\nsecond_from = {:.17g}\nsecond_to = {:.17g}\n"
                      "second_points = {}\n",
                      parameter_name(second.parameter), second.from, second.to, second.points);
  return text;
}

void write_map_file(const RegimeMapOptions& o, const std::map<long, PointResult>& records,
                    const std::string& folder) {
  const std::string path = folder + "/map.csv";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}", path));
  fmt::print(f, "i,j,{},{},{}\n", parameter_name(o.first.parameter),
             parameter_name(o.second.parameter), indicator_header());
  for (const auto& [id, r] : records) {
    const int i = static_cast<int>(id % o.first.points);
    const int j = static_cast<int>(id / o.first.points);
    fmt::print(f, "{},{},{:.17g},{:.17g},{}\n", i, j, o.first.value(i), o.second.value(j),
               indicator_cells(r));
  }
  if (std::fclose(f) != 0) throw Error(fmt::format("cannot finish writing {}", path));
}

}  // namespace pwl::analysis
