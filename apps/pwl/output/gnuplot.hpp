#pragma once
// Runs the shipped gnuplot scripts (plots/scripts/*.gp) through a gnuplot-iostream session: the
// variables a figure needs are streamed to gnuplot, then the script is loaded, so the scripts stay
// plain files that a user edits and runs by hand. Figures are a by-product: a machine without
// gnuplot still gets its CSV files, and a warning instead of a failure. Every figure is drawn
// twice, as PNG and SVG, through plots/scripts/terminal.gp, so that both look alike.
#include <functional>
#include <string>

#include "output/shipped_files.hpp"

namespace pwl::app {

// Runs `script` after the gnuplot commands `definitions` (variable assignments), with the plots
// folder on gnuplot's load path. Returns false and fills *why when gnuplot is missing or fails.
bool run_gnuplot(const std::string& script, const std::string& definitions, std::string* why);

// Draws a figure as PNG and then as SVG: `definitions(format)` gives the variables for "png" or
// "svg" (its out= names the file with that extension; fmt= is added here).
bool draw_figure(const std::string& script,
                 const std::function<std::string(const std::string& format)>& definitions,
                 std::string* why);

// Draws a figure (draw_figure) whose files are `stem`.png and `stem`.svg, and says what became of
// it: "wrote <stem>.png and .svg" on standard output (unless quiet), or "<who>: no figure: <why>"
// on standard error. Returns whether the figure was drawn.
bool draw_figure_and_report(
    const std::string& script,
    const std::function<std::string(const std::string& format)>& definitions,
    const std::string& stem, const std::string& who, bool quiet);

// `text` as a gnuplot single-quoted string literal ('it''s'), for titles and paths. gnuplot reads
// its commands line by line, so a line break inside the literal would end the command there and
// run the rest of the text as commands: control characters (line breaks, tabs, ...) become spaces.
std::string gnuplot_quoted(const std::string& text);


}  // namespace pwl::app
