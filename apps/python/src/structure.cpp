#include "structure.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "pwl/errors.hpp"
#include "scene/scene_structure.hpp"

namespace py = pybind11;

namespace pwl::python {
namespace {

// One spring or load given as a dict with the keys of a scene file's inline tables.
class Entry {
 public:
  Entry(const py::handle& value, std::string name, std::vector<std::string> allowed)
      : name_(std::move(name)) {
    if (!py::isinstance<py::dict>(value)) {
      throw InputError(fmt::format("{}: expected a dict like {{'mass': 1, ...}}, got {}", name_,
                                   py::repr(value).cast<std::string>()));
    }
    dict_ = py::reinterpret_borrow<py::dict>(value);
    for (const auto& [key, item] : dict_) {
      const std::string k = py::str(key).cast<std::string>();
      if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
        throw InputError(fmt::format("{}.{}: unknown; expected one of {}", name_, k,
                                     fmt::join(allowed, ", ")));
      }
    }
  }
  bool has(const char* key) const { return dict_.contains(key) && !dict_[key].is_none(); }
  double number(const char* key, double otherwise) const {
    return has(key) ? require(key) : otherwise;
  }
  double require(const char* key) const {
    if (!has(key)) throw InputError(fmt::format("{}: '{}' is required", name_, key));
    const py::object value = dict_[key];
    double x = std::nan("");
    if (!py::isinstance<py::bool_>(value) && !py::isinstance<py::str>(value)) {
      try {
        x = value.cast<double>();
      } catch (const py::cast_error&) {
      }
    }
    if (!std::isfinite(x)) {
      throw InputError(fmt::format("{}.{} = {}: expected a finite number", name_, key,
                                   py::repr(value).cast<std::string>()));
    }
    return x;
  }
  // A mass numbered 1..n, as a 0-based index.
  int mass(const char* key, Index n) const {
    const double m = require(key);
    if (m != std::floor(m) || m < 1 || m > static_cast<double>(n)) {
      throw InputError(fmt::format("{}.{} = {}: masses are numbered 1..{}", name_, key, m, n));
    }
    return static_cast<int>(m) - 1;
  }

 private:
  std::string name_;
  py::dict dict_;
};

GapStructure make_structure(const py::handle& mass, const py::handle& damping,
                            const py::handle& stiffness, const py::iterable& springs,
                            const py::iterable& loads) {
  const Matrix m = square_matrix(mass, "mass");
  const Index n = m.rows();
  const auto same_size = [&](const py::handle& value, const char* name) {
    if (value.is_none()) return Matrix(Matrix::Zero(n, n));
    Matrix a = square_matrix(value, name);
    if (a.rows() != n) {
      throw InputError(fmt::format("{} is {}x{}; the mass matrix is {}x{}", name, a.rows(),
                                   a.rows(), n, n));
    }
    return a;
  };
  GapStructure g;
  g.mass = to_sparse(m);
  g.damping = to_sparse(same_size(damping, "damping"));
  g.stiffness = to_sparse(same_size(stiffness, "stiffness"));
  int j = 0;
  for (const py::handle item : springs) {
    const Entry e(item, fmt::format("springs[{}]", j++),
                  {"mass", "other_mass", "direction", "stiffness", "gap"});
    GapSpring s;
    s.dof = e.mass("mass", n);
    s.other_dof = e.has("other_mass") ? e.mass("other_mass", n) : -1;
    s.direction = e.number("direction", 1.0);
    s.stiffness = e.require("stiffness");
    s.gap = e.number("gap", 0.0);
    g.springs.push_back(s);
  }
  j = 0;
  for (const py::handle item : loads) {
    const Entry e(item, fmt::format("loads[{}]", j++), {"mass", "amplitude", "omega", "phase"});
    g.loads.push_back(
        {e.mass("mass", n), e.require("amplitude"), e.require("omega"), e.number("phase", 0.0)});
  }
  // The library's check, worded as for a scene's [structure] table.
  std::string why;
  if (!g.is_valid(&why)) throw InputError(fmt::format("structure: {}", why));
  return g;
}

py::list spring_list(const GapStructure& g) {
  py::list springs;
  for (const GapSpring& s : g.springs) {
    py::dict d;
    d["mass"] = s.dof + 1;
    if (s.other_dof >= 0) d["other_mass"] = s.other_dof + 1;
    d["direction"] = s.direction;
    d["stiffness"] = s.stiffness;
    d["gap"] = s.gap;
    springs.append(d);
  }
  return springs;
}

py::list load_list(const GapStructure& g) {
  py::list loads;
  for (const HarmonicLoad& l : g.loads) {
    py::dict d;
    d["mass"] = l.dof + 1;
    d["amplitude"] = l.amplitude;
    d["omega"] = l.omega;
    d["phase"] = l.phase;
    loads.append(d);
  }
  return loads;
}

// The keywords that describe the chain, which an explicit structure replaces.
const std::vector<std::string> kChainKeywords{"figure", "n",     "alpha", "zeta",
                                              "gap",    "gaps",  "theta", "loads"};

}  // namespace

void bind_structure(py::module_& m) {
  py::class_<GapStructure>(m, "Structure", R"doc(
An explicit structure M x'' + C x' + K x = f(t) - W P with gap springs and harmonic loads.

Structure(mass, damping=None, stiffness=None, springs=(), loads=())

mass, damping, stiffness: square matrices (anything NumPy reads; damping and stiffness default to
zero). springs: dicts with the keys of a scene file's spring tables, masses numbered from 1:
{'mass': 2, 'stiffness': 4.0, 'gap': 0.2} ties mass 2 to the ground; 'other_mass': 1 puts the
spring between two masses, 'direction': -1 closes the gap when the displacement shrinks. loads:
dicts {'mass': 2, 'amplitude': 1.0, 'omega': 1.2, 'phase': 0.0} (amplitude sin(omega t + phase)).
The library checks the whole: pwl.InputError naming the field and the value (list and matrix
positions from 0, as in Python: springs[0] is the first spring; masses from 1, as on the command
line). Any job takes it as structure=S, in place of the chain's keywords.)doc")
      .def(py::init(&make_structure), py::arg("mass"), py::arg("damping") = py::none(),
           py::arg("stiffness") = py::none(), py::arg("springs") = py::tuple(),
           py::arg("loads") = py::tuple())
      .def_static(
          "from_scene", [](const std::string& path) { return app::read_scene_structure(path); },
          py::arg("path"), "The [structure] table of a scene file (as --structure-scene reads it).")
      .def_property_readonly("mass",
                             [](const GapStructure& g) { return matrix_array(Matrix(g.mass)); })
      .def_property_readonly("damping",
                             [](const GapStructure& g) { return matrix_array(Matrix(g.damping)); })
      .def_property_readonly(
          "stiffness", [](const GapStructure& g) { return matrix_array(Matrix(g.stiffness)); })
      .def_property_readonly("springs", &spring_list, "The gap springs, as dicts (masses from 1)")
      .def_property_readonly("loads", &load_list, "The harmonic loads, as dicts (masses from 1)")
      .def_property_readonly("dofs", &GapStructure::dofs, "Degrees of freedom (masses)")
      .def_property_readonly(
          "period", [](const GapStructure& g) { return g.common_period(); },
          "The forcing period: the loads' common period (pwl.InputError when there is none)")
      .def("__repr__", [](const GapStructure& g) {
        const auto count = [](std::size_t k, const char* one, const char* many) {
          return fmt::format("{} {}", k, k == 1 ? one : many);
        };
        return fmt::format("pwl.Structure({}, {}, {})",
                           count(static_cast<std::size_t>(g.dofs()), "mass", "masses"),
                           count(g.springs.size(), "gap spring", "gap springs"),
                           count(g.loads.size(), "load", "loads"));
      });
}

std::unique_ptr<app::StructureSceneFile> take_structure(py::dict& kwargs) {
  // A pwl.Structure given where a scene file goes is the structure itself.
  if (kwargs.contains("structure_scene") &&
      py::isinstance<GapStructure>(kwargs["structure_scene"])) {
    if (kwargs.contains("structure") && !kwargs["structure"].is_none()) {
      throw InputError("structure: give an explicit structure or structure_scene, not both");
    }
    kwargs["structure"] = kwargs["structure_scene"];
    PyDict_DelItemString(kwargs.ptr(), "structure_scene");
  }
  if (!kwargs.contains("structure")) return nullptr;
  const py::object value = kwargs["structure"];
  PyDict_DelItemString(kwargs.ptr(), "structure");
  if (value.is_none()) return nullptr;
  if (!py::isinstance<GapStructure>(value)) {
    throw py::type_error(fmt::format("structure: expected a pwl.Structure, got {}",
                                     py::repr(value.get_type()).cast<std::string>()));
  }
  std::vector<std::string> given;
  for (const std::string& k : kChainKeywords) {
    if (kwargs.contains(k) && !kwargs[k.c_str()].is_none()) given.push_back(k);
  }
  if (!given.empty()) {
    throw InputError(fmt::format(
        "structure: the chain's keywords ({}) do not apply to an explicit structure; got {}",
        fmt::join(kChainKeywords, ", "), fmt::join(given, ", ")));
  }
  if (kwargs.contains("structure_scene") && !kwargs["structure_scene"].is_none()) {
    throw InputError("structure: give an explicit structure or structure_scene, not both");
  }
  auto file = std::make_unique<app::StructureSceneFile>(value.cast<const GapStructure&>());
  kwargs["structure_scene"] = file->path();
  return file;
}

std::string name_given_structure(std::string text, const app::StructureSceneFile* file) {
  if (file == nullptr) return text;
  for (std::size_t at = text.find(file->path()); at != std::string::npos;
       at = text.find(file->path(), at)) {
    text.replace(at, file->path().size(), "pwl.Structure");
  }
  return text;
}

}  // namespace pwl::python
