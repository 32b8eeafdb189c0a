#pragma once
// pwl.Structure: an explicit structure from NumPy (M, C, K, gap springs and harmonic loads),
// checked by the library (GapStructure::validate), and how a job takes one: structure=S.
#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "commands/given_structure.hpp"
#include "pwl/model/gap_structure.hpp"

namespace pwl::python {

void bind_structure(pybind11::module_& m);

// Takes the keyword `structure` out of `kwargs` (or `structure_scene` when it is a pwl.Structure). When it is a pwl.Structure, checks that no chain
// keyword (figure, n, alpha, zeta, gap, gaps, theta, loads) nor structure_scene is given with it,
// writes it as a scene file and sets structure_scene to that file, which lives as long as the
// returned object (null without a structure). Throws TypeError for another type, InputError for a
// chain keyword beside it.
std::unique_ptr<app::StructureSceneFile> take_structure(pybind11::dict& kwargs);

// `text` (a job's description of its case) with the path of take_structure's file replaced by
// "pwl.Structure": "the structure of pwl.Structure", not a temporary file that is gone.
std::string name_given_structure(std::string text, const app::StructureSceneFile* file);

}  // namespace pwl::python
