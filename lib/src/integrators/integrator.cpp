#include "pwl/integrators/integrator.hpp"

#include "pwl/errors.hpp"
#include "pwl/integrators/method_table.hpp"

namespace pwl {

void Integrator::advance_with_tangent(double, Matrix&, const StepObserver&) {
  throw InputError(name() + " has no exact tangent map; estimate Lyapunov exponents from two "
                            "nearby trajectories instead");
}

bool Integrator::has_tangent_map() const { return method_traits(method()).tangent_map; }

void Integrator::record_tangent(bool on) {
  if (on) throw InputError(name() + " cannot record its tangent map for replay");
}

bool Integrator::replay_tangent(Matrix&) { return false; }

}  // namespace pwl
