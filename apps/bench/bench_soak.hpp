#pragma once
// `pwl bench soak`: a long sweep that is killed again and again and resumed must end with the
// same files, byte for byte, as one never interrupted (study_runner.hpp, sweep_journal.hpp).
//
// A continuation sweep in θ of the 5-DOF chain of the paper's figure 5, up and down (by default
// 2 x 5000 = 10^4 points of 900 + 100 forcing periods, about a minute on 2 cores), is run once
// uninterrupted, then run again as `pwl sweep ... --resume` processes that are each sent, after a
// random delay, a random one of SIGKILL, SIGTERM and SIGINT (by default 20 of them), and finally
// resumed to the end. The signals and delays come from a seeded generator (the seed is printed;
// --seed repeats the schedule, not the moments the sweep reaches). After every kill the journals
// are read back: a SIGTERM or SIGINT must stop the run with exit code 143 or 130 and whole valid
// lines only; a SIGKILL may leave a torn last line, which the next run cuts off and computes
// again. At the end every file of the folder but the journals must equal the uninterrupted
// run's byte for byte, and the journals must hold the same records.
//
// Prints one row per kill and a summary, writes <out>/bench_soak.csv (one row per kill) and
// <out>/bench_soak.md (the tables), and fails (exit code 1) when a stop was not clean or a file
// differs. Not a test: it takes minutes and its moments are random.
#include <CLI/CLI.hpp>

namespace pwl::app {

// Adds `pwl bench soak` to the bench command.
void add_soak_bench(CLI::App& bench);

}  // namespace pwl::app
