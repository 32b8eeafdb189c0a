#include "pwl/orbits/periodic_orbit.hpp"

#include <Eigen/LU>
#include <cmath>
#include <fmt/format.h>
#include <optional>

#include "orbits/gmres.hpp"
#include "orbits/leading_multipliers.hpp"
#include "orbits/open_structure_preconditioner.hpp"

namespace pwl::orbits {

bool ShootingOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (period < 1) {
    *why = fmt::format("period = {} must be >= 1 (forcing periods per orbit)", period);
    return false;
  }
  if (shots < 1) {
    *why = fmt::format("shots = {} must be >= 1", shots);
    return false;
  }
  if (!(tolerance > 0) || !std::isfinite(tolerance)) {
    *why = fmt::format("tolerance = {} must be positive and finite", tolerance);
    return false;
  }
  if (max_iterations < 1) {
    *why = fmt::format("max iterations = {} must be >= 1", max_iterations);
    return false;
  }
  if (!(max_forcing > 0 && max_forcing < 1)) {
    *why = fmt::format("max forcing = {} must lie in (0, 1) (GMRES's relative residual per Newton "
                       "step at most)",
                       max_forcing);
    return false;
  }
  if (gmres_dimension < 1 || gmres_restarts < 0) {
    *why = fmt::format("gmres dimension = {} must be >= 1 and restarts = {} >= 0",
                       gmres_dimension, gmres_restarts);
    return false;
  }
  if (gmres_recycled < 0 || gmres_recycled >= gmres_dimension) {
    *why = fmt::format("gmres recycled = {} must lie in [0, gmres dimension = {})", gmres_recycled,
                       gmres_dimension);
    return false;
  }
  if (shots > 1 && solver == ShootingSolver::krylov) {
    *why = fmt::format("shots = {}: multiple shooting needs the dense solver", shots);
    return false;
  }
  return arnoldi.is_valid(why);
}

std::string shooting_solver_name(ShootingSolver solver) {
  switch (solver) {
    case ShootingSolver::automatic: return "automatic";
    case ShootingSolver::dense: return "dense";
    case ShootingSolver::krylov: return "krylov";
  }
  return "?";
}

ShootingSolver parse_shooting_solver(const std::string& name) {
  for (ShootingSolver s : {ShootingSolver::automatic, ShootingSolver::dense, ShootingSolver::krylov}) {
    if (shooting_solver_name(s) == name) return s;
  }
  throw InputError(fmt::format("solver = \"{}\" is not known; use automatic, dense or krylov", name));
}

bool uses_dense_solver(const StroboscopicMap& map, const ShootingOptions& options) {
  switch (options.solver) {
    case ShootingSolver::dense: return true;
    case ShootingSolver::krylov: return false;
    case ShootingSolver::automatic: return options.shots > 1 || map.state_size() <= options.dense_state_limit;
  }
  return true;
}

namespace {

// The leading multipliers without the monodromy, preconditioned by `open` where given.
FloquetMultipliers krylov_multipliers(StroboscopicMap& map, const Vector& state,
                                      const ShootingOptions& options,
                                      const detail::OpenStructurePreconditioner* open) {
  ArnoldiOptions arnoldi = options.arnoldi;
  arnoldi.block = map.tangent_block();
  return detail::leading_multipliers(
      [&](Matrix& v) { map.advance(state, options.period, v); }, map.state_size(), arnoldi, open);
}

}  // namespace

FloquetMultipliers orbit_multipliers(StroboscopicMap& map, const Vector& state,
                                     const ShootingOptions& options, Matrix* monodromy) {
  if (uses_dense_solver(map, options)) {
    Matrix M;
    map.advance_with_jacobian(state, options.period, M);
    FloquetMultipliers mu = floquet_multipliers(M);
    if (monodromy != nullptr) *monodromy = std::move(M);
    return mu;
  }
  std::optional<detail::OpenStructurePreconditioner> open;
  if (options.precondition && options.arnoldi.method == ArnoldiOptions::Method::automatic) {
    open.emplace(map.structure(), options.period * map.forcing_period());
  }
  return krylov_multipliers(map, state, options, open ? &*open : nullptr);
}

namespace {

double inf_norm(const Vector& v) { return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>(); }

// The arcs of multiple shooting: m arcs of k T / m each.
struct Arcs {
  int count = 1;
  double length = 0.0;
  double start(int i) const { return i * length; }
};

Arcs make_arcs(const StroboscopicMap& map, const ShootingOptions& options) {
  Arcs arcs;
  arcs.count = options.shots;
  arcs.length = options.period * map.forcing_period() / options.shots;
  if (method_traits(map.settings().method).fixed_grid &&
      (static_cast<long>(options.period) * map.steps_per_period()) % options.shots != 0) {
    throw InputError(fmt::format(
        "shots = {}: the {} steps of the orbit's {} period(s) do not divide into equal arcs",
        options.shots, static_cast<long>(options.period) * map.steps_per_period(),
        options.period));
  }
  return arcs;
}

// The residual of multiple shooting G_i = φ_i(y_i) − y_{i+1 mod m} and, when asked, the arc
// Jacobians M_i.
Vector shooting_residual(StroboscopicMap& map, const Arcs& arcs, const Vector& Y,
                         std::vector<Matrix>* jacobians) {
  const Index N = map.state_size();
  Vector G(Y.size());
  for (int i = 0; i < arcs.count; ++i) {
    const Vector yi = Y.segment(i * N, N);
    Vector end;
    if (jacobians != nullptr) {
      Matrix& Mi = (*jacobians)[i];
      Mi = Matrix::Identity(N, N);
      end = map.flow(yi, arcs.start(i), arcs.start(i) + arcs.length, &Mi);
    } else {
      end = map.flow(yi, arcs.start(i), arcs.start(i) + arcs.length);
    }
    G.segment(i * N, N) = end - Y.segment(((i + 1) % arcs.count) * N, N);
  }
  return G;
}

// The map's integrations and replayed tangent products so far.
struct MapCounts {
  long evaluations = 0, replays = 0;
};
MapCounts counts(const StroboscopicMap& map) { return {map.evaluations(), map.tangent_replays()}; }

PeriodicOrbit finish(StroboscopicMap& map, const ShootingOptions& options, Vector state,
                     double residual, int iterations, bool dense, Matrix monodromy,
                     const MapCounts& before,
                     const detail::OpenStructurePreconditioner* open = nullptr) {
  PeriodicOrbit orbit;
  orbit.state = std::move(state);
  orbit.period = options.period;
  orbit.forcing_period = map.forcing_period();
  orbit.residual = residual;
  orbit.iterations = iterations;
  orbit.exact_tangent = map.exact_tangent();
  orbit.solver = dense ? ShootingSolver::dense : ShootingSolver::krylov;
  if (options.multipliers) {
    if (dense) {
      orbit.multipliers = floquet_multipliers(monodromy);
      orbit.monodromy = std::move(monodromy);
    } else {
      orbit.multipliers = open != nullptr ? krylov_multipliers(map, orbit.state, options, open)
                                          : orbit_multipliers(map, orbit.state, options);
    }
  }
  orbit.evaluations = map.evaluations() - before.evaluations;
  orbit.tangent_replays = map.tangent_replays() - before.replays;
  return orbit;
}

}  // namespace

PeriodicOrbit find_periodic_orbit(StroboscopicMap& map, const Vector& guess,
                                  const ShootingOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  const Index N = map.state_size();
  if (guess.size() != N) {
    throw InputError(fmt::format("guess has {} components, the state {}", guess.size(), N));
  }
  if (!guess.allFinite()) throw InputError("guess is not finite");
  const MapCounts before = counts(map);
  const bool dense = uses_dense_solver(map, options);
  const auto converged = [&](double residual, const Vector& y) {
    return residual <= options.tolerance * std::max(1.0, inf_norm(y));
  };
  const auto fail = [&](const std::string& what, double residual, int iteration) -> ShootingError {
    return ShootingError(
        fmt::format("Newton on the period-{} orbit {} after {} iteration(s): residual |φ(y) − y| = "
                    "{:.3e}, tolerance {:.1e}",
                    options.period, what, iteration, residual, options.tolerance),
        residual, iteration);
  };

  if (dense) {
    const Arcs arcs = make_arcs(map, options);
    const Index size = N * arcs.count;
    // Arc starts from the guess carried along the motion.
    Vector Y(size);
    Y.head(N) = guess;
    for (int i = 1; i < arcs.count; ++i) {
      Y.segment(i * N, N) = map.flow(Y.segment((i - 1) * N, N), arcs.start(i - 1), arcs.start(i));
    }
    std::vector<Matrix> M(arcs.count);
    Vector G = shooting_residual(map, arcs, Y, &M);
    double residual = inf_norm(G);
    for (int iteration = 0;; ++iteration) {
      if (options.on_iteration) options.on_iteration(iteration, residual, 0);
      if (!G.allFinite()) throw fail("met a non-finite state", residual, iteration);
      if (converged(residual, Y)) {
        Matrix monodromy = M[0];
        for (int i = 1; i < arcs.count; ++i) monodromy = M[i] * monodromy;
        return finish(map, options, Y.head(N), residual, iteration, true, std::move(monodromy),
                      before);
      }
      if (iteration == options.max_iterations) throw fail("did not converge", residual, iteration);
      Matrix J = Matrix::Zero(size, size);
      for (int i = 0; i < arcs.count; ++i) {
        J.block(i * N, i * N, N, N) = M[i];
        J.block(i * N, ((i + 1) % arcs.count) * N, N, N) -= Matrix::Identity(N, N);
      }
      Eigen::PartialPivLU<Matrix> lu(J);
      const Vector delta = lu.solve(-G);
      if (!delta.allFinite()) throw fail("met a singular Jacobian (a multiplier at 1)", residual, iteration);
      // Backtracking on |G|_2 (the norm whose decrease the Newton direction guarantees), down to
      // 1/1024 of the step. The full step carries the Jacobians along; a shortened one evaluates
      // the residual alone and the Jacobians only once accepted.
      bool accepted = false;
      for (double lambda = 1.0; lambda >= 1.0 / 1024; lambda /= 2) {
        const Vector trial = Y + lambda * delta;
        try {
          std::vector<Matrix> trial_M(arcs.count);
          Vector trial_G = shooting_residual(map, arcs, trial, lambda == 1.0 ? &trial_M : nullptr);
          if (trial_G.allFinite() && trial_G.norm() < (1 - 1e-4 * lambda) * G.norm()) {
            if (lambda != 1.0) trial_G = shooting_residual(map, arcs, trial, &trial_M);
            Y = trial;
            G = std::move(trial_G);
            M = std::move(trial_M);
            residual = inf_norm(G);
            accepted = true;
            break;
          }
        } catch (const DivergenceError&) {
          // the trial blew up: a shorter step
        }
      }
      if (!accepted) {
        if (residual <= 1e-13 * std::max(1.0, inf_norm(Y))) {
          // At the arithmetic floor: no step decreases the residual further.
          Matrix monodromy = M[0];
          for (int i = 1; i < arcs.count; ++i) monodromy = M[i] * monodromy;
          return finish(map, options, Y.head(N), residual, iteration, true, std::move(monodromy),
                        before);
        }
        throw fail("stalled (no damped step decreases the residual)", residual, iteration);
      }
    }
  }

  // Matrix-free Newton-Krylov, single shooting.
  std::optional<detail::OpenStructurePreconditioner> preconditioner;
  if (options.precondition) {
    preconditioner.emplace(map.structure(), options.period * map.forcing_period());
  }
  double forcing = 1e-2, previous_residual = 0;
  long krylov_products = 0;
  Vector y = guess;
  Vector F = map.advance(y, options.period) - y;
  double residual = inf_norm(F);
  const auto krylov_answer = [&](int iteration) {
    PeriodicOrbit orbit =
        finish(map, options, y, residual, iteration, false, Matrix(), before,
               preconditioner ? &*preconditioner : nullptr);
    orbit.krylov_products = krylov_products;
    orbit.preconditioned = preconditioner && preconditioner->available();
    return orbit;
  };
  detail::RecycledSubspace recycled(options.gmres_recycled, options.gmres_reform);
  for (int iteration = 0;; ++iteration) {
    if (options.on_iteration) options.on_iteration(iteration, residual, krylov_products);
    if (!F.allFinite()) throw fail("met a non-finite state", residual, iteration);
    if (converged(residual, y)) return krylov_answer(iteration);
    if (iteration == options.max_iterations) throw fail("did not converge", residual, iteration);
    // Right-preconditioned GMRES on (M − I) P u = −F, δ = P u.
    const auto precondition = [&](const Vector& v) -> Vector {
      return preconditioner && preconditioner->available() ? preconditioner->apply(v) : v;
    };
    const auto apply = [&](const Vector& v) -> Vector {
      const Vector pv = precondition(v);
      Matrix t = pv;
      map.advance(y, options.period, t);
      return t.col(0) - pv;
    };
    // Eisenstat-Walker forcing, their choice 2 (γ = 0.9, α = 2) with its safeguard (η_k is kept
    // at γ η_{k−1}^2 or above while that exceeds 0.1) and its ceiling η_max (options.max_forcing),
    // never below what the tolerance needs. The ceiling matters: while Newton converges only
    // linearly (iterates far out, where the contacts make the map's derivative change along the
    // step), solving for the step accurately buys nothing and each product costs the most.
    if (iteration > 0) {
      double next = 0.9 * std::pow(residual / previous_residual, 2);
      if (0.9 * forcing * forcing > 0.1) next = std::max(next, 0.9 * forcing * forcing);
      forcing = std::min(next, options.max_forcing);
    }
    forcing = std::max(forcing, 0.5 * options.tolerance * std::max(1.0, inf_norm(y)) / residual);
    Vector u;
    // The map's derivative changes with the iterate: the space is dropped, or its image formed
    // again (ShootingOptions::gmres_reform).
    recycled.operator_changed();
    const detail::GmresResult g = detail::gmres(apply, -F, u, forcing, options.gmres_dimension,
                                                options.gmres_restarts, &recycled);
    krylov_products += g.products;
    const Vector delta = precondition(u);
    previous_residual = residual;
    if (!delta.allFinite()) throw fail("met a singular Jacobian (a multiplier at 1)", residual, iteration);
    bool accepted = false;
    for (double lambda = 1.0; lambda >= 1.0 / 1024; lambda /= 2) {
      const Vector trial = y + lambda * delta;
      try {
        Vector trial_F = map.advance(trial, options.period) - trial;
        const double trial_residual = inf_norm(trial_F);
        // Sufficient decrease of |F|_2, which GMRES minimises.
        if (trial_F.allFinite() && trial_F.norm() < (1 - 1e-4 * lambda) * F.norm()) {
          y = trial;
          F = std::move(trial_F);
          residual = trial_residual;
          accepted = true;
          break;
        }
      } catch (const DivergenceError&) {
      }
    }
    if (!accepted) {
      if (residual <= 1e-13 * std::max(1.0, inf_norm(y))) return krylov_answer(iteration);
      throw fail("stalled (no damped step decreases the residual)", residual, iteration);
    }
  }
}

PeriodicOrbit at_minimal_period(StroboscopicMap& map, const PeriodicOrbit& orbit,
                                const ShootingOptions& options) {
  const int k = orbit.period;
  const double scale = 1e3 * options.tolerance * std::max(1.0, inf_norm(orbit.state));
  for (int m = 1; m < k; ++m) {
    if (k % m != 0) continue;
    if (inf_norm(map.advance(orbit.state, m) - orbit.state) > scale) continue;
    ShootingOptions reduced = options;
    reduced.period = m;
    if (m % reduced.shots != 0) reduced.shots = 1;
    return find_periodic_orbit(map, orbit.state, reduced);
  }
  return orbit;
}

}  // namespace pwl::orbits
