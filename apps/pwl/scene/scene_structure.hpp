#pragma once
// An explicit structure in a scene file: M, C and K as rows, gap springs and harmonic loads as
// lists of inline tables (scene.hpp shows the form). Masses are numbered from 1 in the file, as
// everywhere on the command line.
#include <string>
#include <string_view>

#include "pwl/model/gap_structure.hpp"

namespace pwl::app {

// Reads the [structure] table of the scene text. Throws InputError naming the file, line, key
// and what was expected (a ragged or non-square matrix, sizes that differ, a spring on a mass that
// does not exist, ...), or GapStructure::validate()'s message (a mass matrix that is not positive
// definite, a negative stiffness, ...).
GapStructure parse_scene_structure(std::string_view text, const std::string& name);

// The same for the file at `path`.
GapStructure read_scene_structure(const std::string& path);

}  // namespace pwl::app
