#include "pwl/integrators/pim_integrator.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/numerics/state_checks.hpp"
#include "integrators/fixed_sizes.hpp"
#include "integrators/fixed_step_count.hpp"
#include "pwl/integrators/precise_propagator.hpp"

namespace pwl {

bool PimOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  return check_step_settings(step, divergence_bound, why) && exponential.is_valid(why);
}

namespace {

template <int Dofs, int Springs>
class PimIntegrator final : public Integrator {
 public:
  PimIntegrator(const PimStepOperators& ops, const PimOptions& options)
      : propagator_(ops, make_lcp_solver(options.lcp_solver), options.divergence_bound),
        solver_name_(lcp_algorithm_name(options.lcp_solver)) {
    position_ = Vector::Zero(propagator_.dofs());
    velocity_ = position_;
  }

  std::string name() const override {
    return fmt::format("pim (step {:.6g}, {})", propagator_.step_size(), solver_name_);
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
    advance(t_end, nullptr, observer);
  }

  Method method() const override { return Method::pim_dense; }
  void advance_with_tangent(double t_end, Matrix& tangent, const StepObserver& observer) override {
    advance(t_end, &tangent, observer);
  }

  IntegratorStats stats() const override { return stats_; }

 private:
  void advance(double t_end, Matrix* tangent, const StepObserver& observer) {
    const auto publish = [this] { sync(); };
    const auto advance_by = [&](auto&& step) {
      stats_.steps += detail::advance_on_grid(t_end, propagator_.time(), propagator_.step_size(),
                                              observer, position_, velocity_, step, publish);
    };
    if constexpr (Dofs != Eigen::Dynamic && Dofs == Springs) {
      // One tangent vector on fixed-size storage (λ1 alone): the single-vector map.
      if (tangent != nullptr && tangent->cols() == 1 && tangent->rows() == 2 * Dofs) {
        typename PrecisePropagator<Dofs, Springs>::StateVector y = *tangent;
        advance_by([&] {
          propagator_.step();
          propagator_.apply_step_tangent_vector(y);
          stats_.lcp_pivots += propagator_.last_lcp_pivots();
          return propagator_.time();
        });
        *tangent = y;
        return;
      }
    }
    advance_by([&] {
      propagator_.step();
      if (tangent != nullptr) propagator_.apply_step_tangent(*tangent);
      stats_.lcp_pivots += propagator_.last_lcp_pivots();
      return propagator_.time();
    });
  }

  void sync() {
    position_ = propagator_.position();
    velocity_ = propagator_.velocity();
  }

  PrecisePropagator<Dofs, Springs> propagator_;
  std::string solver_name_;
  Vector position_, velocity_;
  IntegratorStats stats_;
};

// Fixed-size fast paths for the small square cases (one gap spring per mass), up to
// detail::kFixedSizes masses (integrators/fixed_sizes.hpp).
template <int N>
std::unique_ptr<Integrator> make_fixed(const PimStepOperators& ops, const PimOptions& options) {
  if constexpr (N > 0) {
    if (ops.directions.rows() == N && ops.directions.cols() == N) {
      return std::make_unique<PimIntegrator<N, N>>(ops, options);
    }
    return make_fixed<N - 1>(ops, options);
  } else {
    return std::make_unique<PimIntegrator<Eigen::Dynamic, Eigen::Dynamic>>(ops, options);
  }
}

}  // namespace

std::unique_ptr<Integrator> make_pim_integrator(const GapStructure& structure,
                                                const PimOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("pim options: " + why);
  const PimStepOperators ops = make_pim_step_operators(structure, options.step, options.exponential);
  return make_fixed<detail::kFixedSizes>(ops, options);
}

}  // namespace pwl
