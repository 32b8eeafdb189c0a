#pragma once
// An explicit structure given in memory (the Python module's pwl.Structure) to a job whose flags
// take one only as a scene file (--structure-scene, case_options.hpp and study_runner.hpp): the
// structure is written as a scene's [structure] table into a private temporary folder, and the job
// reads it back through the same reader and checks as any scene (scene_structure.hpp). Numbers are
// written with 17 significant digits, so the job integrates the same doubles.
#include <string>

#include "pwl/model/gap_structure.hpp"

namespace pwl::app {

// The [structure] table of a scene (mass, damping, stiffness as rows; spring and load as lists of
// inline tables, masses numbered from 1). Throws InputError for a structure that is not valid
// (GapStructure::validate's message).
std::string structure_scene_text(const GapStructure& structure);

// structure_scene_text in <temporary folder>/structure.toml, removed with the object.
class StructureSceneFile {
 public:
  // Throws pwl::Error when the file cannot be written.
  explicit StructureSceneFile(const GapStructure& structure);
  ~StructureSceneFile();
  StructureSceneFile(const StructureSceneFile&) = delete;
  StructureSceneFile& operator=(const StructureSceneFile&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string folder_;
  std::string path_;
};

}  // namespace pwl::app
