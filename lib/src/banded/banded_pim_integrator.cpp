// The banded precise-integration stepper of He, Gao & Zhong, Appl. Math. Mech. 39(7) (2018)
// 737-749, behind the Integrator concept.
#include "pwl/integrators/banded_pim_integrator.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pwl/integrators/banded_propagator.hpp"
#include "pwl/errors.hpp"
#include "pwl/numerics/state_checks.hpp"
#include "integrators/fixed_step_count.hpp"
#include "pwl/numerics/substructure_exponential.hpp"

namespace pwl {

bool BandedPimOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  return check_step_settings(step, divergence_bound, why) &&
         check_nested(band.is_valid(why), "band", why) &&
         check_nested(lcp.is_valid(why), "lcp", why);
}

BandedLayout banded_layout(const GapStructure& structure) {
  BandedLayout out;
  const Index n = structure.dofs();
  out.diagonal_mass = true;
  for (Index j = 0; j < structure.mass.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(structure.mass, j); it; ++it) {
      if (it.row() != j && it.value() != 0.0) out.diagonal_mass = false;
    }
  }
  for (const SparseMatrix* A : {&structure.damping, &structure.stiffness}) {
    for (Index j = 0; j < A->outerSize(); ++j) {
      for (SparseMatrix::InnerIterator it(*A, j); it; ++it) {
        if (it.value() != 0.0) out.dof_bandwidth = std::max(out.dof_bandwidth, std::abs(it.row() - j));
      }
    }
  }
  for (const GapSpring& s : structure.springs) {
    if (s.other_dof >= 0) out.spring_reach = std::max<Index>(out.spring_reach, std::abs(s.dof - s.other_dof));
  }
  out.cell_dofs = detect_cell_size(structure);
  const Index reach = std::max(out.dof_bandwidth, out.spring_reach);
  if (!out.diagonal_mass) {
    out.why_not = "the mass matrix is not diagonal";
  } else if (8 * reach >= n) {
    out.why_not = fmt::format("couplings reach {} degrees of freedom, too far for {} in all",
                              reach, n);
  } else {
    out.banded = true;
  }
  return out;
}

namespace {

class BandedPimIntegrator final : public Integrator {
 public:
  BandedPimIntegrator(BandedStepOperators ops, const BandedPimOptions& options)
      : propagator_(std::move(ops), options.lcp, options.divergence_bound) {
    position_ = Vector::Zero(propagator_.dofs());
    velocity_ = position_;
  }

  Method method() const override { return Method::pim_banded; }
  std::string name() const override {
    return fmt::format("pim-banded (step {:.6g}, band {})", propagator_.step_size(),
                       propagator_.operators().truncation.band);
  }
  Index dofs() const override { return propagator_.dofs(); }

  void set_state(double t, const Vector& x, const Vector& v) override {
    propagator_.set_state(t, x, v);
    sync();
  }
  double time() const override { return propagator_.time(); }
  const Vector& position() const override { return position_; }
  const Vector& velocity() const override { return velocity_; }

  void advance_to(double t_end, const StepObserver& observer) override {
    stats_.steps += detail::advance_on_grid(
        t_end, propagator_.time(), propagator_.step_size(), observer, position_, velocity_,
        [&] {
          propagator_.step();
          stats_.lcp_pivots += propagator_.last_lcp_pivots();
          return propagator_.time();
        },
        [this] { sync(); });
  }

  IntegratorStats stats() const override { return stats_; }

 private:
  void sync() {
    propagator_.position(position_);
    propagator_.velocity(velocity_);
  }

  BandedPropagator propagator_;
  Vector position_, velocity_;
  IntegratorStats stats_;
};

}  // namespace

std::unique_ptr<Integrator> make_banded_pim_integrator(const GapStructure& structure,
                                                       const BandedPimOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("banded pim options: " + why);
  structure.validate();
  const BandedLayout layout = banded_layout(structure);
  if (!layout.diagonal_mass) {
    throw InputError("banded pim: " + layout.why_not +
                     "; the banded method needs a lumped mass (use the dense pim)");
  }
  BandedExponentialOptions band = options.band;
  if (band.cell_dofs == 0) band.cell_dofs = layout.cell_dofs;
  return std::make_unique<BandedPimIntegrator>(
      make_banded_step_operators(structure, options.step, band), options);
}

std::unique_ptr<Integrator> make_pim_integrator_auto(const GapStructure& structure,
                                                     const PimOptions& options,
                                                     Index banded_above) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("pim options: " + why);
  structure.validate();
  if (structure.dofs() > banded_above && banded_layout(structure).banded) {
    BandedPimOptions b;
    b.step = options.step;
    // The most doublings carry over; the substructures keep their own series and trimming
    // (banded_exponential.hpp), so `pim` and `pim-banded` are the same stepper on a long chain.
    b.band.exponential.doublings = options.exponential.doublings;
    b.divergence_bound = options.divergence_bound;
    return make_banded_pim_integrator(structure, b);
  }
  return make_pim_integrator(structure, options);
}

}  // namespace pwl
