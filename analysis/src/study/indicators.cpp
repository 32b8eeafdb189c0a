#include "pwl/study/indicators.hpp"

#include <fmt/format.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace pwl::analysis {
namespace {

// The accessors of each row. A real or integer field is read and written through its member.
template <double PointResult::*kField>
IndicatorValue get_real(const PointResult& r) {
  return r.*kField;
}
template <double PointResult::*kField>
void set_real(PointResult& r, const IndicatorValue& v) {
  r.*kField = std::get<double>(v);
}
template <int PointResult::*kField>
IndicatorValue get_integer(const PointResult& r) {
  return static_cast<long>(r.*kField);
}
template <int PointResult::*kField>
void set_integer(PointResult& r, const IndicatorValue& v) {
  r.*kField = static_cast<int>(std::get<long>(v));
}
template <std::string PointResult::*kField>
IndicatorValue get_text(const PointResult& r) {
  return r.*kField;
}
template <std::string PointResult::*kField>
void set_text(PointResult& r, const IndicatorValue& v) {
  r.*kField = std::get<std::string>(v);
}
IndicatorValue get_regime(const PointResult& r) { return r.regime; }
void set_regime(PointResult& r, const IndicatorValue& v) { r.regime = std::get<std::string>(v); }
IndicatorValue get_confirmed_by(const PointResult& r) { return r.confirmed_by; }
IndicatorValue get_disagreement(const PointResult& r) { return r.disagreement; }
void set_disagreement(PointResult& r, const IndicatorValue& v) {
  r.disagreement = std::get<std::string>(v);
}
void set_confirmed_by(PointResult& r, const IndicatorValue& v) {
  r.confirmed_by = std::get<std::string>(v);
}
IndicatorValue get_code(const PointResult& r) {
  return static_cast<long>(regime_code(r.regime, r.period));
}

// The table. Append new rows at the end: the result files' existing columns keep their places.
constexpr std::array<Indicator, 22> kIndicators{{
    {"regime", "the classified motion: period-k, quasi-periodic, chaotic, unbounded, uncertain",
     IndicatorType::text, false, "failed", get_regime, set_regime},
    {"code", "the regime as a small integer for colour maps (regime_code)", IndicatorType::integer,
     true, "", get_code, nullptr},
    {"period", "k of a period-k motion, 0 otherwise", IndicatorType::integer, false, "",
     get_integer<&PointResult::period>, set_integer<&PointResult::period>},
    {"lambda1", "the largest Lyapunov exponent per forcing period", IndicatorType::real, false, "",
     get_real<&PointResult::lambda1>, set_real<&PointResult::lambda1>},
    {"lambda1_error", "the uncertainty of lambda1 (largest of three estimates, lyapunov.hpp)",
     IndicatorType::real, false, "", get_real<&PointResult::lambda1_error>,
     set_real<&PointResult::lambda1_error>},
    {"K", "K of the 0-1 test for chaos on the observable (near 0 regular, near 1 chaotic)",
     IndicatorType::real, false, "", get_real<&PointResult::K>, set_real<&PointResult::K>},
    {"settle_periods",
     "orbit refinement settled the regime: forcing periods still needed to reach the orbit (0: on "
     "it); empty when the regime is the record's own",
     IndicatorType::real, false, "", get_real<&PointResult::settle_periods>,
     set_real<&PointResult::settle_periods>},
    {"extra_periods",
     "adaptive evidence: periods recorded beyond the setting because the indicators disagreed",
     IndicatorType::integer, false, "", get_integer<&PointResult::extra_periods>,
     set_integer<&PointResult::extra_periods>},
    {"confirmed_by",
     "the method whose run decided the point when an approximate method's verdict was checked "
     "(exact); empty otherwise",
     IndicatorType::text, false, "", get_confirmed_by, set_confirmed_by},
    {"attractors",
     "coexisting attractors reached from the point's starts (--starts > 1); 0 when not counted",
     IndicatorType::integer, false, "", get_integer<&PointResult::attractors>,
     set_integer<&PointResult::attractors>},
    {"torus_digits",
     "torus test of a record without a period: digits on which the weighted Birkhoff averages of "
     "its halves agree (smooth invariant curve: high; chaos: 1 to 2)",
     IndicatorType::real, false, "", get_real<&PointResult::torus_digits>,
     set_real<&PointResult::torus_digits>},
    {"rotation",
     "rotation number of a record without a period in the (x1, x2) plane (x1, v1 for one mass), "
     "turns per forcing period",
     IndicatorType::real, false, "", get_real<&PointResult::rotation>,
     set_real<&PointResult::rotation>},
    {"chaotic_transient",
     "transient chaos: forcing periods the motion wandered chaotically before it settled on its "
     "period-k orbit; 0 when none was found",
     IndicatorType::integer, false, "", get_integer<&PointResult::chaotic_transient>,
     set_integer<&PointResult::chaotic_transient>},
    {"disagreement",
     "for an uncertain point, what each indicator read (period, lambda1, K, torus; or a period "
     "Newton did not confirm), one token; empty otherwise",
     IndicatorType::text, false, "", get_disagreement, set_disagreement},
    {"minimal_period",
     "Newton's check of a period verdict: the orbit's minimal period (the smallest m dividing the "
     "period found whose map closes it); 0 when no Newton checked the period",
     IndicatorType::integer, false, "", get_integer<&PointResult::minimal_period>,
     set_integer<&PointResult::minimal_period>},
    {"multiplier",
     "the largest modulus of the checked orbit's Floquet multipliers at its minimal period",
     IndicatorType::real, false, "", get_real<&PointResult::multiplier>,
     set_real<&PointResult::multiplier>},
    {"record_period",
     "the period the record's own search found (0: none), before Newton reduced or refinement "
     "found it",
     IndicatorType::integer, false, "", get_integer<&PointResult::record_period>,
     set_integer<&PointResult::record_period>},
    {"decided_by", "the method the verdict rests on: the point's own or the one that confirmed it",
     IndicatorType::text, false, "", get_text<&PointResult::decided_by>,
     set_text<&PointResult::decided_by>},
    {"confirmation",
     "how the accurate method checked the verdict: newton (its orbit at that period) or motion "
     "(its own run from the same start); empty when not checked",
     IndicatorType::text, false, "", get_text<&PointResult::confirmation>,
     set_text<&PointResult::confirmation>},
    {"observed_periods",
     "forcing periods the verdict's indicators were measured over (record and adaptive evidence)",
     IndicatorType::integer, false, "", get_integer<&PointResult::observed_periods>,
     set_integer<&PointResult::observed_periods>},
    {"halves",
     "chaotic or quasi-periodic verdict: agree when lambda1, K and the torus test read the same "
     "over both halves of the record, else differ: and the indicators that changed",
     IndicatorType::text, false, "", get_text<&PointResult::halves>,
     set_text<&PointResult::halves>},
    {"rotation_pq",
     "a period above 8 or an orbit locked on a torus: its rotation as p/q, q the period",
     IndicatorType::text, false, "", get_text<&PointResult::rotation_pq>,
     set_text<&PointResult::rotation_pq>},
}};

std::string cell(const Indicator& indicator, const PointResult& r) {
  const IndicatorValue v = indicator.get(r);
  switch (indicator.type) {
    case IndicatorType::text: {
      const std::string& text = std::get<std::string>(v);
      return text.empty() ? std::string(indicator.empty_text) : text;
    }
    case IndicatorType::integer:
      return fmt::format("{}", std::get<long>(v));
    case IndicatorType::real: {
      const double x = std::get<double>(v);
      return std::isnan(x) ? std::string() : fmt::format("{:.17g}", x);
    }
  }
  return {};
}

}  // namespace

std::span<const Indicator> indicators() { return kIndicators; }

const Indicator* find_indicator(std::string_view name) {
  for (const Indicator& i : kIndicators) {
    if (i.name == name) return &i;
  }
  return nullptr;
}

std::string indicator_header() {
  std::string s;
  for (const Indicator& i : kIndicators) s += fmt::format("{}{}", s.empty() ? "" : ",", i.name);
  return s;
}

std::string indicator_cells(const PointResult& r) {
  std::string s;
  bool first = true;
  for (const Indicator& i : kIndicators) {
    s += first ? "" : ",";
    s += cell(i, r);
    first = false;
  }
  return s;
}

std::string indicator_tokens(const PointResult& r) {
  std::string s;
  for (const Indicator& i : kIndicators) {
    if (i.derived) continue;
    const IndicatorValue v = i.get(r);
    switch (i.type) {
      case IndicatorType::text: {
        // A token has no blanks; "-" stands for empty text.
        const std::string& text = std::get<std::string>(v);
        s += " " + (text.empty() ? std::string("-") : text);
        break;
      }
      case IndicatorType::integer:
        s += fmt::format(" {}", std::get<long>(v));
        break;
      case IndicatorType::real:
        s += fmt::format(" {:.17g}", std::get<double>(v));
        break;
    }
  }
  return s;
}

bool read_indicator_token(const Indicator& indicator, std::string_view token, PointResult& r) {
  if (indicator.derived || indicator.set == nullptr || token.empty()) return false;
  const std::string s(token);
  switch (indicator.type) {
    case IndicatorType::text:
      indicator.set(r, s == "-" ? std::string() : s);
      return true;
    case IndicatorType::integer: {
      char* end = nullptr;
      errno = 0;
      const long v = std::strtol(s.c_str(), &end, 10);
      if (errno != 0 || end != s.c_str() + s.size()) return false;
      indicator.set(r, v);
      return true;
    }
    case IndicatorType::real: {
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (end != s.c_str() + s.size()) return false;
      indicator.set(r, v);
      return true;
    }
  }
  return false;
}

}  // namespace pwl::analysis
