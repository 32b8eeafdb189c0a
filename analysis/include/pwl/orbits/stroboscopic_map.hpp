#pragma once
// The stroboscopic map of a periodically forced structure, the object every periodic-orbit
// computation of pwl works on.
//
// A structure forced with period T is a non-autonomous system; sampled at t = 0 mod T (the phase of
// `poincare.csv`) its motion is the iteration of one map, P(y) = φ_T(y), on the state y = [x; x'].
// A period-k orbit is a fixed point of P^k = φ_{kT}. The map is advanced by any integrator of the
// method table. The integrator is built once and re-used: every evaluation sets its state at the
// start time and advances to the end, so a construction that costs (the exponentials of the PIM)
// is paid once per structure.
//
// Derivatives. The vector field of a gap-spring structure is continuous and piecewise linear, so
// the Jacobian of φ is the product of the exact exponentials of the linear pieces the motion passes
// through, with no saltation jump at a contact (R. I. Leine and H. Nijmeijer, Dynamics and
// Bifurcation of Non-Smooth Mechanical Systems, Springer 2004, ch. 7). The integrators that have an
// exact tangent map (method_traits(m).tangent_map: the exact solver, the PIM, the switching PIM)
// push tangent vectors along with the state; for the others the products come from forward
// differences of the flow (J v ≈ (φ(y + εv) − φ(y))/ε, ε = √eps (1 + |y|)/|v|: the Jacobian-free
// products of D. A. Knoll and D. E. Keyes, J. Comput. Phys. 193 (2004) 357-397), which are about
// eight digits accurate and make Newton converge all the same, but give Floquet multipliers to
// only about that accuracy. `exact_tangent()` says which.
//
// Repeated products. Krylov methods (the GMRES of Newton-Krylov shooting, Arnoldi for the
// multipliers) multiply many vectors by one Jacobian, each product a tangent integration from the
// same state. When the integrator can record its tangent map (Integrator::can_record_tangent: the
// banded switching PIM) the map records it on every evaluation, with or without products, and
// replays it for the products that follow from the same state over the same span, without
// integrating the state again; the products are the same to the last bit. So the first GMRES
// product after Newton's line search has accepted a state is a replay of the line search's own
// integration (plain integrations are recorded over at most 64 forcing periods). Another state or
// span, or a caller that takes the integrator, ends the record.
//
// Products of several columns on two threads. From kSpreadStateSize state components on, a
// product of several columns is split in two halves, the second applied by a second integrator of
// the same structure (built on first use) in parallel with the first (where OpenMP has more than
// one thread and the call is not already inside a parallel region). The second integrator records
// the same arc once and replays it as the first does; every column goes through the same
// arithmetic on either, so the products are the same to the last bit on any number of threads.
// A block Krylov method (Arnoldi with ArnoldiOptions::block = tangent_block()) is what hands the
// map two columns at a time.
#include <functional>
#include <memory>

#include "pwl/integrators/integrator.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/study/point_model.hpp"
#include "pwl/types.hpp"

namespace pwl::orbits {

class StroboscopicMap {
 public:
  // The map over one forcing period of `point`, advanced by the method `settings` names (its step
  // and largest step are set from the period by MethodSettings::for_period). Throws InputError
  // for an invalid structure, period or settings.
  StroboscopicMap(const analysis::PointCase& point, const MethodSettings& settings,
                  int steps_per_period);
  ~StroboscopicMap();
  StroboscopicMap(StroboscopicMap&&) noexcept;
  StroboscopicMap& operator=(StroboscopicMap&&) noexcept;

  const GapStructure& structure() const { return point_.structure; }
  double forcing_period() const { return point_.period; }
  Index dofs() const { return point_.structure.dofs(); }
  Index state_size() const { return 2 * dofs(); }
  // The settings the integrator was built with (step set from the period).
  const MethodSettings& settings() const { return settings_; }
  int steps_per_period() const { return steps_per_period_; }
  // Whether tangent products are exact (the method's tangent map) or forward differences.
  bool exact_tangent() const;
  // Columns worth handing to one tangent product: 2 where products of several columns are split
  // over two integrators (recorded tangent maps, at least kSpreadStateSize state components), 1
  // elsewhere. Fixed by the structure, not by the threads of the machine, so that a block
  // method's answer is the same everywhere.
  int tangent_block() const;
  static constexpr Index kSpreadStateSize = 1000;

  // The state `periods` forcing periods after y: φ_{kT}(y), started at t = start_period · T. Loads
  // are T-periodic, so the start period changes nothing but the clock; it is there so that the
  // arcs of a multiple-shooting orbit can be integrated each from its own time. Throws
  // DivergenceError when the motion blows up.
  Vector advance(const Vector& y, int periods, int start_period = 0);
  // The same, and `tangent` (2n x p) is replaced by J · tangent, J = ∂φ_{kT}/∂y at y.
  Vector advance(const Vector& y, int periods, Matrix& tangent, int start_period = 0);
  // The flow from time t0 to t1 (> t0; on the step grid for a fixed-grid method), with the
  // tangent products when `tangent` is given: the arcs of multiple shooting.
  Vector flow(const Vector& y, double t0, double t1, Matrix* tangent = nullptr);
  // φ_{kT}(y) and the whole Jacobian (2n x 2n).
  Vector advance_with_jacobian(const Vector& y, int periods, Matrix& jacobian);

  // The integrator, for a caller that samples the motion along the orbit (orbit_profile). Its
  // state is whatever the last evaluation left; the next tangent product integrates again.
  Integrator& integrator() {
    replay_ready_ = false;
    return *integrator_;
  }

  // Called before every integration of the map (each advance, flow, tangent product that is not
  // replayed): a caller that abandons the work on a signal (a study told to stop) throws from it.
  // Empty: nothing is called. The map's results never depend on it.
  void set_checkpoint(std::function<void()> checkpoint) { checkpoint_ = std::move(checkpoint); }

  // Evaluations of the map so far (each one an integration of `periods` periods; the forward
  // differences count one per column). Replayed tangent products are not integrations: they are
  // counted by tangent_replays().
  long evaluations() const { return evaluations_; }
  long tangent_replays() const { return replays_; }

 private:
  struct Twin {};
  // A second map of the same structure and settings (the other half of a split product).
  StroboscopicMap(const StroboscopicMap& primary, Twin);
  Vector integrate(const Vector& y, double t0, double t1, Matrix* tangent);
  // integrate() on this map's own integrator only.
  Vector integrate_here(const Vector& y, double t0, double t1, Matrix* tangent);
  // integrate() with the tangent's columns split between this map and its twin, in parallel.
  Vector integrate_split(const Vector& y, double t0, double t1, Matrix& tangent);
  bool splits(const Matrix& tangent) const;

  analysis::PointCase point_;
  MethodSettings settings_;
  int steps_per_period_ = 0;
  std::unique_ptr<Integrator> integrator_;
  long evaluations_ = 0;
  long replays_ = 0;
  std::function<void()> checkpoint_;
  // Plain integrations longer than this many forcing periods are not recorded.
  static constexpr int kReplayPeriods = 64;
  bool recording_ = false;  // the integrator's record_tangent
  // The last recorded integration, whose record the integrator holds: its start, span and end.
  bool replay_ready_ = false;
  Vector base_start_, base_end_;
  double base_t0_ = 0.0, base_t1_ = 0.0;
  std::unique_ptr<StroboscopicMap> twin_;  // built on the first split product
};

}  // namespace pwl::orbits
