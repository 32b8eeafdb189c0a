#pragma once
// The checks of a sequence of Poincaré points that the period search and the classifier share, so
// that they refuse the same input with the same message.
#include <vector>

#include "pwl/types.hpp"

namespace pwl::analysis::detail {

// Throws InputError unless `points` is non-empty, its first point has a non-zero dimension and
// every point has that dimension; with `finite`, also unless every entry is finite. The message
// names the first offending point (and entry).
void check_points(const std::vector<Vector>& points, bool finite);

}  // namespace pwl::analysis::detail
