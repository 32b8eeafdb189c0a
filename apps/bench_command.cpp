// pwl bench: speed and accuracy measurements (subcommands are added as they are built).
#include "commands.hpp"

namespace pwl::app {
void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks: print tables and write CSV");
  bench->require_subcommand(1);
}
}  // namespace pwl::app
