#include "pwl/integrators/integrator.hpp"

#include "pwl/errors.hpp"

namespace pwl {

void Integrator::advance_with_tangent(double, Matrix&, const StepObserver&) {
  throw InputError(name() + " has no exact tangent map; estimate Lyapunov exponents from two "
                            "nearby trajectories instead");
}

}  // namespace pwl
