#include "commands/given_structure.hpp"

#include <fmt/format.h>
#include <stdlib.h>  // mkdtemp

#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

#include "output/csv_writer.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {


std::string rows(const Matrix& m) {
  std::string text = "[";
  for (Index i = 0; i < m.rows(); ++i) {
    text += i > 0 ? ",\n  [" : "[";
    for (Index j = 0; j < m.cols(); ++j) text += (j > 0 ? ", " : "") + full_precision(m(i, j));
    text += "]";
  }
  return text + "]";
}

}  // namespace

std::string structure_scene_text(const GapStructure& g) {
  g.validate();
  std::string text = "[structure]\n";
  text += "mass = " + rows(Matrix(g.mass)) + "\n";
  text += "damping = " + rows(Matrix(g.damping)) + "\n";
  text += "stiffness = " + rows(Matrix(g.stiffness)) + "\n";
  text += "spring = [";
  for (std::size_t j = 0; j < g.springs.size(); ++j) {
    const GapSpring& s = g.springs[j];
    text += fmt::format("{}{{ mass = {}{}, direction = {}, stiffness = {}, gap = {} }}",
                        j > 0 ? ",\n  " : "", s.dof + 1,
                        s.other_dof >= 0 ? fmt::format(", other_mass = {}", s.other_dof + 1) : "",
                        full_precision(s.direction), full_precision(s.stiffness), full_precision(s.gap));
  }
  text += "]\nload = [";
  for (std::size_t j = 0; j < g.loads.size(); ++j) {
    const HarmonicLoad& l = g.loads[j];
    text += fmt::format("{}{{ mass = {}, amplitude = {}, omega = {}, phase = {} }}",
                        j > 0 ? ",\n  " : "", l.dof + 1, full_precision(l.amplitude), full_precision(l.omega),
                        full_precision(l.phase));
  }
  return text + "]\n";
}

StructureSceneFile::StructureSceneFile(const GapStructure& structure) {
  const std::string text = structure_scene_text(structure);
  std::string pattern = (std::filesystem::temp_directory_path() / "pwl-structure-XXXXXX").string();
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (::mkdtemp(buffer.data()) == nullptr) {
    throw Error(fmt::format("cannot make a temporary folder like {}", pattern));
  }
  folder_ = buffer.data();
  path_ = folder_ + "/structure.toml";
  std::ofstream out(path_, std::ios::binary);
  out << text;
  if (!out.flush()) {
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
    throw Error(fmt::format("cannot write {}", path_));
  }
}

StructureSceneFile::~StructureSceneFile() {
  std::error_code ignored;
  std::filesystem::remove_all(folder_, ignored);
}

}  // namespace pwl::app
