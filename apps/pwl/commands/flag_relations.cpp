#include "commands/flag_relations.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "pwl/errors.hpp"

namespace pwl::app {

const std::vector<FlagRelation>& flag_relations() {
  using K = FlagRelationKind;
  static const std::vector<FlagRelation> relations{
      {"simulate", "--skip-periods", "--periods", K::below, false,
       "it would leave nothing to record"},
      {"continue", "--min-step", "--max-step", K::at_most, true, ""},
      {"continue", "--min-step", "--step", K::at_most, true,
       "the branch would stop at its first step"},
      {"continue", "--curves", "--parameter", K::differs, false,
       "a curve lies in the plane of two parameters"},
      {"map", "--y", "--x", K::differs, false, "both axes would vary one parameter"},
      {"basin", "--y", "--x", K::differs, false, "both axes would vary one state component"},
      {"basin", "--kept-points", "--periods", K::at_most, false,
       "only the recorded periods can be kept"},
      {"bench soak", "--min-delay", "--max-delay", K::at_most, true, ""},
  };
  return relations;
}

namespace {

const FlagRelation& relation_of(const std::string& job, const std::string& first,
                                const std::string& second) {
  for (const FlagRelation& r : flag_relations()) {
    if (r.job == job && r.first == first && r.second == second) return r;
  }
  throw std::logic_error(fmt::format("pwl {}: no relation between {} and {} in the table of "
                                     "flag_relations.cpp",
                                     job, first, second));
}

std::string because(const FlagRelation& r) { return r.why.empty() ? "" : " (" + r.why + ")"; }

}  // namespace

void check_relation(const std::string& job, const std::string& first, double a,
                    const std::string& second, double b) {
  const FlagRelation& r = relation_of(job, first, second);
  if (r.zero_is_default && (a == 0.0 || b == 0.0)) return;
  if (r.kind == FlagRelationKind::at_most && !(a <= b)) {
    throw InputError(
        fmt::format("{} = {} must be at most {} = {}{}", first, a, second, b, because(r)));
  }
  if (r.kind == FlagRelationKind::below && !(a < b)) {
    throw InputError(
        fmt::format("{} = {} must be below {} = {}{}", first, a, second, b, because(r)));
  }
  if (r.kind == FlagRelationKind::differs && a == b) {
    throw InputError(
        fmt::format("{} = {} must differ from {} = {}{}", first, a, second, b, because(r)));
  }
}

void check_relation(const std::string& job, const std::string& first, const std::string& a,
                    const std::string& second, const std::string& b) {
  const FlagRelation& r = relation_of(job, first, second);
  if (r.kind != FlagRelationKind::differs) {
    throw std::logic_error(fmt::format("pwl {}: {} and {} are compared as numbers", job, first,
                                       second));
  }
  if (a == b) {
    throw InputError(
        fmt::format("{} = {} must differ from {} = {}{}", first, a, second, b, because(r)));
  }
}

}  // namespace pwl::app
