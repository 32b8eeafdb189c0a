#pragma once
// The indicators of a study point, registered once: every number or name the pipeline gives a
// point (regime, period, λ1, ...) is a row of one table, which says what it is called, what it
// means, how it reads and writes. The journal (sweep_journal.hpp) and the result files of sweeps
// and maps (classification.csv, map.csv) go through the table and name no indicator, so that a new
// indicator (say the Floquet multipliers) is its field in PointResult, its row here and the code
// in evaluate_point that computes it.
//
// Columns keep the table's order, so files written before a row was appended read the same.
// Reals are written with 17 significant digits (they read back as the same double); in the result
// files NaN (not computed) is an empty cell, in the journal the token "nan".
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

// The value of one indicator: text, an integer or a real (NaN: not computed).
using IndicatorValue = std::variant<std::string, long, double>;

enum class IndicatorType { text, integer, real };

struct Indicator {
  std::string_view name;     // the column of the result files: "lambda1"
  std::string_view meaning;  // one line, for documentation and messages
  IndicatorType type;
  // Derived from other indicators (regime code from regime and period): written to the result
  // files, not to the journal, never set.
  bool derived;
  // What the result files write for empty text ("failed" for a regime never set).
  std::string_view empty_text;
  IndicatorValue (*get)(const PointResult& result);
  void (*set)(PointResult& result, const IndicatorValue& value);  // null when derived
};

// Every indicator, in column order.
std::span<const Indicator> indicators();
// The row called `name`, or null.
const Indicator* find_indicator(std::string_view name);

// The result files' header cells of every indicator, comma separated ("regime,code,period,...").
std::string indicator_header();
// The cells of one point, comma separated, in the header's order.
std::string indicator_cells(const PointResult& result);

// The journal's tokens of the non-derived indicators, each preceded by a space.
std::string indicator_tokens(const PointResult& result);
// Reads one journal token of `indicator` into `result`; false when it does not parse.
bool read_indicator_token(const Indicator& indicator, std::string_view token,
                          PointResult& result);

}  // namespace pwl::analysis
