#pragma once
// Runs a gnuplot script. Figures are a by-product: a machine without gnuplot still gets its CSV
// files, and a warning instead of a failure.
#include <string>

namespace pwl::app {

// Runs `gnuplot -e "<definitions>" <script>`. Returns false and fills *why when gnuplot is missing
// or fails.
bool run_gnuplot(const std::string& script, const std::string& definitions, std::string* why);

// The folder of the shipped gnuplot scripts (plots/ of the source tree, or an installed copy).
std::string plots_directory();

}  // namespace pwl::app
