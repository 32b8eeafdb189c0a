#pragma once
// The evidence ladder of one study point, stage by stage. evaluate_point (sweep_point.cpp) is the
// list of these calls; each stage is one file of this folder and reads and writes one PointRun:
//
//   record_stage        the motion integrated past its transient, its stroboscopic points
//                       recorded, classified (indicator_stage), and recorded longer while the
//                       indicators disagree (adaptive evidence)
//   indicator_stage     λ1, K (also on every k-th point: banded chaos), the torus test and the
//                       classifier's verdict on a record
//   newton_stage        a period verdict checked by Newton at its period (minimal period, on the
//                       orbit or approaching it, leading multiplier); a record without a period
//                       refined by Newton at candidate periods and at its rotation's denominator
//   transient_stage     a motion that ends on a cycle: whether it wandered chaotically first
//   observation_stage   what the verdict was seen over: the periods, the halves of a record
//                       without a period, the rotation p/q of a long or locked period
//   confirmation_stage  a fixed-step method's verdict checked by a method whose error cannot
//                       move it (the exact solver, or the switching PIM beyond its size)
//   attractor_stage     more starts, and the distinct attractors they reach
//
// A stage added is one file here and one line in evaluate_point. What each stage decides and why
// is in analysis/README.md, "How a verdict is reached". Each stage's test, in tests/study/:
// point_evidence_test (record, adaptive evidence), point_torus_test and the banded chaos of
// point_evidence_test (indicators), point_period_check_test and point_refinement_test (Newton),
// point_transient_test, point_observation_test, point_confirmation_test, point_starts_test
// (attractors).
#include <string>
#include <string_view>
#include <vector>

#include "pwl/analysis/motion_classifier.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/orbits/orbit_refinement.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis::ladder {

// One evaluation of a point with one method: what the stages pass down.
struct PointRun {
  PointRun(const PointCase& p, const Vector& start, const PointSettings& s, PointObserver* o)
      : point(p), initial_state(start), settings(s), observer(o) {}

  const PointCase& point;
  const Vector& initial_state;
  const PointSettings& settings;
  PointObserver* observer;  // may be null

  // The record's stroboscopic states [x; v] at phase `settings.section.phase`, in order, and
  // (small structures: kRefinedMasses degrees of freedom at most) the transient's before them.
  std::vector<Vector> points;
  std::vector<Vector> history;
  // The record's one-period tangent growth (1x1) or Jacobians, one per point, when λ1 came from
  // the method's tangent map; else empty. And the time of the first point, in forcing periods.
  std::vector<Matrix> jacobians;
  double first_point_time = 1.0;
  // The record's own verdict (the classifier's, before Newton and the other stages).
  Classification classification;
  bool classified = false;  // false: the motion blew up or a contact problem failed
  // The last stroboscopic states the verdict rests on (at most kTailPoints; attractor_stage
  // matches them), empty for a motion that blew up or failed.
  std::vector<Vector> tail;
  PointResult result;

  // Tells the observer that a stage ended (PointObserver::stage_finished).
  void finished(std::string_view stage) const {
    if (observer != nullptr) observer->stage_finished(stage);
  }
  // PointObserver::checkpoint: may throw to abandon the point.
  void checkpoint() const {
    if (observer != nullptr) observer->checkpoint();
  }
  // The same, before every integration of a Newton stage's map.
  void watch(orbits::StroboscopicMap& map) const {
    if (observer != nullptr) map.set_checkpoint([o = observer] { o->checkpoint(); });
  }
};

// Passes on the checkpoints alone: what a confirming run by the accurate method is observed by,
// so that a study told to stop stops it too, while the caller's files see only the first run.
class CheckpointsOnly : public PointObserver {
 public:
  explicit CheckpointsOnly(PointObserver* to) : to_(to) {}
  void checkpoint() override {
    if (to_ != nullptr) to_->checkpoint();
  }

 private:
  PointObserver* to_;
};

constexpr std::size_t kTailPoints = 64;

// record_stage.cpp. Validates the settings and the initial state (InputError), then fills
// points, history, classification and result (regime, period, λ1, K, torus, extra periods,
// observed periods, decided_by, final state). A blow-up is "unbounded", an unsolvable contact
// problem or the exact solver's spent budget "failed"; neither is thrown.
void record_stage(PointRun& run);

// indicator_stage.cpp. The indicators of `points` (stroboscopic states in order; `jacobians`
// their one-period growth factors, 1x1, or Jacobians, one per point, when the method gives its
// tangent map; else empty) and the classifier's verdict. `first_point_time` is the time of the
// first point in forcing periods from the initial state (the growth rule of the classifier).
// `lambda1`, `lambda1_error`, `K`, `torus_digits` and `rotation` of `result` are set (NaN when not
// computed); λ1 by two trajectories is measured here too when the settings ask for it.
struct RecordIndicators {
  const PointCase& point;
  const PointSettings& settings;
  const MethodSettings& method;
  bool tangent;  // jacobians hold the tangent's growth
};
Classification indicator_stage(const RecordIndicators& record, const std::vector<Vector>& points,
                               const std::vector<Matrix>& jacobians, double first_point_time,
                               PointResult& result);
// The component the 0-1 test reads.
int observable_of(const PointSettings& settings, Index dofs);

// newton_stage.cpp.
void newton_stage(PointRun& run);
// Newton's settings for a check of `period` on a structure of `dofs` degrees of freedom, by this
// stage and by the confirmation's Newton on the accurate map: that period alone, and beyond
// kRefinedMasses the approach to an attracting orbit followed for at most kLargeCheckPeriods
// periods (each costs a long chain's period) instead of refinement's 20000.
constexpr int kLargeCheckPeriods = 2000;
orbits::RefinementOptions period_check(int period, Index dofs);

// transient_stage.cpp. Also fills run.tail.
void transient_stage(PointRun& run);

// observation_stage.cpp.
void observation_stage(PointRun& run);

// confirmation_stage.cpp. The method that checks `method`'s verdicts on `point`, or none
// (Method::pim when there is none: the caller asks `has` first).
struct AccurateMethod {
  bool has = false;
  Method method = Method::exact;
};
AccurateMethod accurate_method_for(const PointCase& point, const PointSettings& settings);
void confirmation_stage(PointRun& run);
// Whether confirmation_stage will run the point again by the accurate method for its present
// verdict (an uncertain or quasi-periodic one, as the settings say): newton_stage then leaves the
// refinement to that run, whose map decides.
bool rerun_by_accurate_method(const PointRun& run);

// attractor_stage.cpp.
void attractor_stage(PointRun& run);

// One run of the ladder up to (not including) the confirmation: what confirmation_stage runs
// again with the accurate method; and the whole ladder but the attractors, what every start of
// attractor_stage goes through (sweep_point.cpp lists both).
void run_with_method(PointRun& run);
void evaluate_ladder(PointRun& run);

// Small helpers the stages share (record_stage.cpp).
Matrix as_rows(const std::vector<Vector>& states);
Matrix initial_tangent(Index size);
// The averaging of λ1 over `count` periods of a record of `recorded`: the first min(50,
// recorded/5) align the tangent vector, frame or separation; the rest are averaged in up to 10
// blocks.
struct Averaging {
  long transient = 0;
  long iterations = 0;
  int blocks = 0;
  bool enough() const { return blocks >= 2; }
};
Averaging averaging(long count, int recorded);

}  // namespace pwl::analysis::ladder
