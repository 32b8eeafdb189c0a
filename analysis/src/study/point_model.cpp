#include "pwl/study/point_model.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "pwl/errors.hpp"

namespace pwl::analysis {

std::string SweepParameter::name() const {
  switch (kind_) {
    case Kind::theta: return "theta";
    case Kind::alpha: return "alpha";
    case Kind::zeta: return "zeta";
    case Kind::gap: return "gap";
    case Kind::amplitude: return "amplitude";
    case Kind::spring_stiffness: return fmt::format("spring{}.stiffness", index_ + 1);
    case Kind::spring_gap: return fmt::format("spring{}.gap", index_ + 1);
    case Kind::load_amplitude: return fmt::format("load{}.amplitude", index_ + 1);
    case Kind::load_frequency: return fmt::format("load{}.frequency", index_ + 1);
    case Kind::damping: return "damping";
  }
  return "theta";
}

std::string parameter_name(const SweepParameter& parameter) { return parameter.name(); }

SweepParameter parse_sweep_parameter(const std::string& name) {
  if (name == "theta") return SweepParameter::theta;
  if (name == "alpha") return SweepParameter::alpha;
  if (name == "zeta") return SweepParameter::zeta;
  if (name == "gap" || name == "delta") return SweepParameter::gap;
  if (name == "amplitude") return SweepParameter::amplitude;
  throw InputError(fmt::format(
      "parameter = \"{}\" is not known; the chain's parameters are theta, alpha, zeta, gap (or "
      "delta) and amplitude (an explicit structure, --structure-scene, has spring<j>.stiffness, "
      "spring<j>.gap, load<j>.amplitude, load<j>.frequency and damping)",
      name));
}

NondimensionalChain with_parameter(const NondimensionalChain& base,
                                   const SweepParameter& parameter, double value) {
  NondimensionalChain c = base;
  switch (parameter.kind()) {
    case SweepParameter::Kind::theta: c.theta = value; break;
    case SweepParameter::Kind::alpha: c.alpha = {value}; break;
    case SweepParameter::Kind::zeta: c.zeta = value; break;
    case SweepParameter::Kind::gap: c.gap = {value}; break;
    case SweepParameter::Kind::amplitude:
      for (double& q : c.amplitude) q *= value;
      break;
    default:
      throw InputError(fmt::format("parameter = \"{}\" belongs to an explicit structure, not to "
                                   "the chain",
                                   parameter.name()));
  }
  return c;
}

GapStructure with_parameter(const GapStructure& base, const SweepParameter& parameter,
                            double value) {
  GapStructure g = base;
  const auto index = static_cast<std::size_t>(parameter.index());
  const auto need = [&](std::size_t count, const char* what) {
    if (parameter.index() < 0 || index >= count) {
      throw InputError(fmt::format("parameter = \"{}\": the structure has {} {}", parameter.name(),
                                   count, what));
    }
  };
  switch (parameter.kind()) {
    case SweepParameter::Kind::spring_stiffness:
      need(g.springs.size(), "gap springs");
      g.springs[index].stiffness = value;
      break;
    case SweepParameter::Kind::spring_gap:
      need(g.springs.size(), "gap springs");
      g.springs[index].gap = value;
      break;
    case SweepParameter::Kind::load_amplitude:
      need(g.loads.size(), "loads");
      g.loads[index].amplitude = value;
      break;
    case SweepParameter::Kind::load_frequency:
      need(g.loads.size(), "loads");
      g.loads[index].omega = value;
      break;
    case SweepParameter::Kind::damping:
      g.damping = value * base.damping;
      break;
    default:
      throw InputError(fmt::format("parameter = \"{}\" belongs to the chain, not to an explicit "
                                   "structure",
                                   parameter.name()));
  }
  return g;
}

PointCase::PointCase(GapStructure s, double t) : structure(std::move(s)), period(t) {}

PointCase::PointCase(const NondimensionalChain& chain)
    : structure(make_chain(chain)), period(chain.period()) {}

PointModel::PointModel(NondimensionalChain chain) : chain_(std::move(chain)) {}

PointModel::PointModel(ExplicitStructure structure) : structure_(std::move(structure)) {}

const ExplicitStructure& PointModel::structure() const {
  if (!structure_) throw Error("point model: the chain has no explicit structure");
  return *structure_;
}

int PointModel::dofs() const {
  return structure_ ? static_cast<int>(structure_->structure.dofs()) : chain_.masses;
}

std::vector<std::string> PointModel::parameter_names() const {
  if (!structure_) return {"theta", "alpha", "zeta", "gap", "amplitude"};
  std::vector<std::string> names;
  const GapStructure& g = structure_->structure;
  for (std::size_t j = 0; j < g.springs.size(); ++j) {
    names.push_back(SweepParameter::spring_stiffness(static_cast<int>(j)).name());
    names.push_back(SweepParameter::spring_gap(static_cast<int>(j)).name());
  }
  for (std::size_t j = 0; j < g.loads.size(); ++j) {
    names.push_back(SweepParameter::load_amplitude(static_cast<int>(j)).name());
    names.push_back(SweepParameter::load_frequency(static_cast<int>(j)).name());
  }
  names.push_back("damping");
  return names;
}

namespace {

// "spring12.gap" -> ("spring", 12, "gap"); false when `name` does not have that form.
bool split_numbered(const std::string& name, std::string* part, long* number,
                    std::string* field) {
  const std::size_t digits = name.find_first_of("0123456789");
  const std::size_t dot = name.find('.');
  if (digits == std::string::npos || dot == std::string::npos || digits == 0 || dot <= digits) {
    return false;
  }
  const std::string count = name.substr(digits, dot - digits);
  if (count.find_first_not_of("0123456789") != std::string::npos || count.size() > 9) return false;
  *part = name.substr(0, digits);
  *number = std::strtol(count.c_str(), nullptr, 10);
  *field = name.substr(dot + 1);
  return true;
}

}  // namespace

SweepParameter PointModel::parameter(const std::string& name) const {
  if (!structure_) return parse_sweep_parameter(name);
  const GapStructure& g = structure_->structure;
  const std::string accepted = fmt::format("{}", fmt::join(parameter_names(), ", "));
  if (name == "damping") return SweepParameter::damping_scale();
  std::string part, field;
  long number = 0;
  if (split_numbered(name, &part, &number, &field)) {
    const bool spring = part == "spring" && (field == "stiffness" || field == "gap");
    const bool load = part == "load" && (field == "amplitude" || field == "frequency");
    if (spring || load) {
      const long count = static_cast<long>(spring ? g.springs.size() : g.loads.size());
      if (number < 1 || number > count) {
        throw InputError(fmt::format(
            "parameter = \"{}\": {} has {} {} ({}); its parameters: {}", name, structure_->source,
            count, spring ? "gap springs" : "loads",
            count == 0 ? std::string("none")
                       : fmt::format("{0}1..{0}{1}", part, count),
            accepted));
      }
      const int index = static_cast<int>(number - 1);
      if (spring) {
        return field == "stiffness" ? SweepParameter::spring_stiffness(index)
                                    : SweepParameter::spring_gap(index);
      }
      return field == "amplitude" ? SweepParameter::load_amplitude(index)
                                  : SweepParameter::load_frequency(index);
    }
  }
  throw InputError(fmt::format("parameter = \"{}\" is not known: it is not a parameter of {}; its "
                               "parameters: {}",
                               name, structure_->source, accepted));
}

bool PointModel::has(const SweepParameter& p, std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (p.of_chain() == explicit_structure()) {
    *why = fmt::format("parameter = \"{}\" is not a parameter of {}; its parameters: {}", p.name(),
                       structure_ ? structure_->source : std::string("the chain"),
                       fmt::join(parameter_names(), ", "));
    return false;
  }
  if (!structure_) return true;
  try {
    parameter(p.name());
  } catch (const InputError& e) {
    *why = e.what();
    return false;
  }
  return true;
}

bool PointModel::accepts(const SweepParameter& p, double value, std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!has(p, why)) return false;
  if (!std::isfinite(value)) {
    *why = fmt::format("{} = {} must be finite", p.name(), value);
    return false;
  }
  if (p == SweepParameter::theta && !(value > 0.0)) {
    *why = fmt::format("theta = {} must be positive", value);
    return false;
  }
  if (p.kind() == SweepParameter::Kind::load_frequency && !(value > 0.0)) {
    *why = fmt::format("{} = {} must be positive (the forcing period is 2π/ω)", p.name(), value);
    return false;
  }
  if (p.kind() == SweepParameter::Kind::damping && !(value >= 0.0)) {
    *why = fmt::format("damping = {} must be >= 0 (it scales the damping matrix)", value);
    return false;
  }
  try {
    const PointCase c = with(p, value).point_case();
    if (!(c.period > 0.0) || !std::isfinite(c.period)) {
      *why = fmt::format("{} = {}: the forcing period {} is not positive", p.name(), value,
                         c.period);
      return false;
    }
  } catch (const InputError& e) {
    *why = fmt::format("{} = {}: {}", p.name(), value, e.what());
    return false;
  }
  return true;
}

PointModel PointModel::with(const SweepParameter& p, double value) const {
  if (!structure_) return PointModel(with_parameter(chain_, p, value));
  return PointModel(ExplicitStructure{with_parameter(structure_->structure, p, value),
                                      structure_->source, structure_->label});
}

double PointModel::value(const SweepParameter& p) const {
  std::string why;
  if (!has(p, &why)) throw InputError(why);
  const auto single = [&](const std::vector<double>& values) {
    for (double v : values) {
      if (v != values.front()) {
        throw InputError(fmt::format("{}: the masses have different values ({} and {}); a curve "
                                     "in {} needs one",
                                     p.name(), values.front(), v, p.name()));
      }
    }
    return values.front();
  };
  const auto index = static_cast<std::size_t>(p.index());
  switch (p.kind()) {
    case SweepParameter::Kind::theta: return chain_.theta;
    case SweepParameter::Kind::alpha: return single(chain_.alpha);
    case SweepParameter::Kind::zeta: return chain_.zeta;
    case SweepParameter::Kind::gap: return single(chain_.gap);
    case SweepParameter::Kind::amplitude: return 1.0;
    case SweepParameter::Kind::spring_stiffness:
      return structure_->structure.springs[index].stiffness;
    case SweepParameter::Kind::spring_gap: return structure_->structure.springs[index].gap;
    case SweepParameter::Kind::load_amplitude: return structure_->structure.loads[index].amplitude;
    case SweepParameter::Kind::load_frequency: return structure_->structure.loads[index].omega;
    case SweepParameter::Kind::damping: return 1.0;
  }
  return 0.0;
}

PointCase PointModel::point_case() const {
  if (!structure_) return PointCase(chain_);
  structure_->structure.validate();
  return PointCase(structure_->structure, structure_->structure.common_period());
}

namespace {

std::string doubles(const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt::format("{}{:.17g}", i ? "," : "", v[i]);
  return s;
}

std::string rows(const SparseMatrix& sparse) {
  const Matrix m(sparse);
  std::string s;
  for (Index i = 0; i < m.rows(); ++i) {
    s += i ? ";" : "";
    for (Index j = 0; j < m.cols(); ++j) s += fmt::format("{}{:.17g}", j ? "," : "", m(i, j));
  }
  return s;
}

}  // namespace

std::string PointModel::describe() const {
  if (!structure_) {
    return fmt::format(
        "masses = {}\nalpha = {}\nzeta = {:.17g}\ngap = {}\ntheta = {:.17g}\namplitude = {}\n",
        chain_.masses, doubles(chain_.alpha), chain_.zeta, doubles(chain_.gap), chain_.theta,
        doubles(chain_.amplitude));
  }
  const GapStructure& g = structure_->structure;
  std::string s = fmt::format("model = {}\nmass = {}\ndamping = {}\nstiffness = {}\n",
                              structure_->source, rows(g.mass), rows(g.damping),
                              rows(g.stiffness));
  for (std::size_t j = 0; j < g.springs.size(); ++j) {
    const GapSpring& k = g.springs[j];
    s += fmt::format("spring{} = dof {}, other {}, direction {:.17g}, stiffness {:.17g}, "
                     "gap {:.17g}\n",
                     j + 1, k.dof + 1, k.other_dof + 1, k.direction, k.stiffness, k.gap);
  }
  for (std::size_t j = 0; j < g.loads.size(); ++j) {
    const HarmonicLoad& f = g.loads[j];
    s += fmt::format("load{} = dof {}, amplitude {:.17g}, omega {:.17g}, phase {:.17g}\n", j + 1,
                     f.dof + 1, f.amplitude, f.omega, f.phase);
  }
  return s;
}

}  // namespace pwl::analysis
