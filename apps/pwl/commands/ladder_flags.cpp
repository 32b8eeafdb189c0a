#include "commands/ladder_flags.hpp"

#include <fmt/format.h>

#include "commands/cli_checks.hpp"

namespace pwl::app {

void LadderFlags::apply(analysis::PointSettings& s) const {
  analysis::PointSettings defaults;
  if (!quick) defaults.use_ladder();
  s.refine_max_period = refine_orbits >= 0 ? refine_orbits : defaults.refine_max_period;
  s.evidence_periods = evidence_periods >= 0 ? evidence_periods : defaults.evidence_periods;
  s.confirm = confirm.empty() ? defaults.confirm : analysis::parse_confirmation(confirm);
  s.check_periods = defaults.check_periods;
}

void add_ladder_flags(CLI::App& c, LadderFlags& f) {
  using analysis::PointSettings;
  c.add_flag("--quick", f.quick,
             "The plain record: no adaptive evidence, no orbit refinement, no Newton check of the\n"
             "periods and no confirmation by the accurate method (each flag below still sets its\n"
             "step). Default: the whole evidence ladder (analysis/README.md, \"How a verdict is\n"
             "reached\")");
  c.add_option("--refine-orbits", f.refine_orbits,
               "Orbit refinement of quasi-periodic and uncertain points (up to 20 masses): Newton\n"
               "on the stroboscopic map at candidate periods up to this many forcing periods; a\n"
               "periodic orbit the motion is on or is confirmed to approach makes the point\n"
               "period-k (settle_periods: the periods it still needs). 0: off")
      ->check(number_in(0, 1000))
      ->default_str(fmt::format("{} (0 with --quick)", PointSettings::kLadderRefinePeriod));
  c.add_option("--evidence-periods", f.evidence_periods,
               "Adaptive evidence: an uncertain point records longer, doubling its record, until\n"
               "its indicators agree or this many more periods are spent (extra_periods). 0: off")
      ->check(non_negative_number())
      ->default_str(fmt::format("{} (0 with --quick)", PointSettings::kLadderEvidencePeriods));
  c.add_option("--confirm", f.confirm,
               "Verdicts of an approximate method (the PIM) checked by one whose error cannot move\n"
               "them (the exact solver up to 20 masses, the switching PIM beyond): none; uncertain\n"
               "(run again); aperiodic (uncertain, chaotic and quasi-periodic run again); regular\n"
               "(periods checked by Newton on the accurate map, its motion where Newton fails;\n"
               "uncertain and quasi-periodic run again); all (regular, and chaotic run again).\n"
               "confirmed_by, confirmation and decided_by say what did")
      ->check(CLI::IsMember({"none", "uncertain", "aperiodic", "regular", "all"}))
      ->default_str("regular (none with --quick)");
}

}  // namespace pwl::app
