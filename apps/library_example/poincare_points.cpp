// A forced oscillator with a one-sided stop, built by hand and stepped by the precise integration
// method: prints its Poincaré points (one per forcing period, after a transient) and how far they
// are from the exact event-driven solution of the same motion.
//
//   x'' + 0.1 x' + x + 4 max(0, x - 0.2) = sin(1.2 t)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <pwl/integrators/event_driven_solver.hpp>
#include <pwl/model/gap_structure.hpp>
#include <pwl/integrators/pim_integrator.hpp>

int main() {
  pwl::GapStructure s;
  s.mass = pwl::to_sparse(pwl::Matrix::Identity(1, 1));
  s.damping = pwl::to_sparse(pwl::Matrix::Constant(1, 1, 0.1));
  s.stiffness = pwl::to_sparse(pwl::Matrix::Identity(1, 1));
  s.springs.push_back({.dof = 0, .stiffness = 4.0, .gap = 0.2});
  s.loads.push_back({.dof = 0, .amplitude = 1.0, .omega = 1.2});

  const double period = 2 * std::numbers::pi / 1.2;
  auto pim = pwl::make_pim_integrator(s, {.step = period / 200});
  auto exact = pwl::make_event_driven_solver(s);
  for (auto* m : {pim.get(), exact.get()})
    m->set_state(0.0, pwl::Vector::Zero(1), pwl::Vector::Zero(1));

  double largest = 0.0;
  std::printf("period     x (PIM)        x' (PIM)\n");
  for (int k = 1; k <= 300; ++k) {
    pim->advance_to(k * period);
    exact->advance_to(k * period);
    if (k <= 290) continue;  // transient
    std::printf("%4d  %14.10f  %14.10f\n", k, pim->position()[0], pim->velocity()[0]);
    largest = std::max({largest, std::abs(pim->position()[0] - exact->position()[0]),
                        std::abs(pim->velocity()[0] - exact->velocity()[0])});
  }
  std::printf("PIM (eta = T/200) and the exact solver agree to %.2e\n", largest);
  return largest < 1e-2 ? 0 : 1;
}
