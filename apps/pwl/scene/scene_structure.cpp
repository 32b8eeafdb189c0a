#include "scene/scene_structure.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "pwl/errors.hpp"
#include "scene/scene.hpp"

namespace pwl::app {
namespace {

std::string at(const std::string& name, const toml::node& node) {
  return fmt::format("{}:{}:{}", name, node.source().begin.line, node.source().begin.column);
}

double number(const toml::node& node, const std::string& name, const std::string& key) {
  if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
  if (const auto* d = node.as_floating_point()) {
    if (std::isfinite(d->get())) return d->get();
  }
  throw InputError(fmt::format("{}: {}: expected a finite number", at(name, node), key));
}

// A square matrix given as rows.
Matrix matrix(const toml::node& node, const std::string& name, const std::string& key) {
  const auto* rows = node.as_array();
  if (rows == nullptr || rows->empty()) {
    throw InputError(fmt::format(
        "{}: {}: expected a matrix as a list of rows, e.g. [[1, 0], [0, 1]]", at(name, node), key));
  }
  const auto n = static_cast<Index>(rows->size());
  Matrix m(n, n);
  for (Index i = 0; i < n; ++i) {
    const auto* row = rows->get(static_cast<std::size_t>(i))->as_array();
    if (row == nullptr || static_cast<Index>(row->size()) != n) {
      throw InputError(
          fmt::format("{}: {}: row {} must be a list of {} numbers (the matrix is square)",
                      at(name, *rows->get(static_cast<std::size_t>(i))), key, i + 1, n));
    }
    for (Index j = 0; j < n; ++j) {
      m(i, j) = number(*row->get(static_cast<std::size_t>(j)), name,
                       fmt::format("{}[{}][{}]", key, i + 1, j + 1));
    }
  }
  return m;
}

// The entries of one inline table of a list ("spring" or "load"), each checked for its type.
class Entry {
 public:
  Entry(const toml::node& node, const std::string& name, std::string key)
      : name_(name), key_(std::move(key)), node_(node), table_(node.as_table()) {
    if (table_ == nullptr) {
      throw InputError(
          fmt::format("{}: {}: expected a table like {{ mass = 1, ... }}", at(name_, node), key_));
    }
  }
  // Rejects keys outside `allowed`.
  void only(std::initializer_list<std::string_view> allowed) const {
    for (auto&& [k, v] : *table_) {
      if (std::find(allowed.begin(), allowed.end(), k.str()) == allowed.end()) {
        throw InputError(fmt::format("{}: {}.{}: unknown; expected one of {}", at(name_, v), key_,
                                     k.str(), fmt::join(allowed, ", ")));
      }
    }
  }
  std::optional<double> get(std::string_view k) const {
    const toml::node* v = table_->get(k);
    if (v == nullptr) return std::nullopt;
    return number(*v, name_, fmt::format("{}.{}", key_, k));
  }
  double require(std::string_view k) const {
    const std::optional<double> v = get(k);
    if (!v) throw InputError(fmt::format("{}: {}: '{}' is required", at(name_, node_), key_, k));
    return *v;
  }
  // A mass number 1..n, as a zero-based index.
  int mass(std::string_view k, Index n) const {
    const double m = require(k);
    if (m != std::floor(m) || m < 1 || m > static_cast<double>(n)) {
      throw InputError(fmt::format("{}: {}.{} = {}: masses are numbered 1..{}", at(name_, node_),
                                   key_, k, m, n));
    }
    return static_cast<int>(m) - 1;
  }

 private:
  const std::string& name_;
  std::string key_;
  const toml::node& node_;
  const toml::table* table_;
};

const toml::array* list(const toml::table& s, std::string_view key, const std::string& name) {
  const toml::node* node = s.get(key);
  if (node == nullptr) return nullptr;
  const auto* a = node->as_array();
  if (a == nullptr) {
    throw InputError(
        fmt::format("{}: structure.{}: expected a list of tables, e.g. [{{ mass = 1, ... }}]",
                    at(name, *node), key));
  }
  return a;
}

}  // namespace

GapStructure parse_scene_structure(std::string_view text, const std::string& name) {
  const std::string screened = screen_scene_text(text, name);
  toml::table doc;
  try {
    doc = toml::parse(screened, name);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: {}", name, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
  const toml::table* s = doc["structure"].as_table();
  if (s == nullptr || s->get("mass") == nullptr) {
    throw InputError(
        fmt::format("{}: structure.mass: an explicit structure needs its mass matrix", name));
  }
  const Matrix m = matrix(*s->get("mass"), name, "structure.mass");
  const Index n = m.rows();
  const auto same_size = [&](std::string_view key) {
    const toml::node* node = s->get(key);
    if (node == nullptr) return Matrix(Matrix::Zero(n, n));
    Matrix a = matrix(*node, name, fmt::format("structure.{}", key));
    if (a.rows() != n) {
      throw InputError(fmt::format("{}: structure.{} is {}x{}; the mass matrix is {}x{}",
                                   at(name, *node), key, a.rows(), a.rows(), n, n));
    }
    return a;
  };
  GapStructure g;
  g.mass = to_sparse(m);
  g.damping = to_sparse(same_size("damping"));
  g.stiffness = to_sparse(same_size("stiffness"));
  if (const toml::array* springs = list(*s, "spring", name)) {
    for (std::size_t i = 0; i < springs->size(); ++i) {
      const Entry e(*springs->get(i), name, fmt::format("structure.spring[{}]", i + 1));
      e.only({"mass", "other_mass", "direction", "stiffness", "gap"});
      GapSpring spring;
      spring.dof = e.mass("mass", n);
      spring.other_dof = e.get("other_mass") ? e.mass("other_mass", n) : -1;
      spring.direction = e.get("direction").value_or(1.0);
      spring.stiffness = e.require("stiffness");
      spring.gap = e.get("gap").value_or(0.0);
      g.springs.push_back(spring);
    }
  }
  if (const toml::array* loads = list(*s, "load", name)) {
    for (std::size_t i = 0; i < loads->size(); ++i) {
      const Entry e(*loads->get(i), name, fmt::format("structure.load[{}]", i + 1));
      e.only({"mass", "amplitude", "omega", "phase"});
      g.loads.push_back({e.mass("mass", n), e.require("amplitude"), e.require("omega"),
                         e.get("phase").value_or(0.0)});
    }
  }
  std::string why;
  if (!g.is_valid(&why)) throw InputError(fmt::format("{}: structure: {}", name, why));
  return g;
}

GapStructure read_scene_structure(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("--structure-scene {}: cannot read the file", path));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene_structure(text.str(), path);
}

}  // namespace pwl::app
