#include "pwl/orbits/stroboscopic_map.hpp"

#include <omp.h>

#include <cmath>
#include <exception>
#include <fmt/format.h>
#include <limits>

#include "pwl/errors.hpp"

namespace pwl::orbits {

StroboscopicMap::StroboscopicMap(const analysis::PointCase& point, const MethodSettings& settings,
                                 int steps_per_period)
    : point_(point), steps_per_period_(steps_per_period) {
  if (!(std::isfinite(point.period) && point.period > 0)) {
    throw InputError(fmt::format("forcing period = {} must be positive and finite", point.period));
  }
  if (method_traits(settings.method).fixed_grid && steps_per_period < 1) {
    throw InputError(fmt::format("steps per period = {} must be >= 1", steps_per_period));
  }
  settings_ = settings.for_period(point.period, steps_per_period);
  integrator_ = make_integrator(point_.structure, settings_);
  recording_ = integrator_->can_record_tangent();
  if (recording_) integrator_->record_tangent(true);
}

StroboscopicMap::StroboscopicMap(const StroboscopicMap& primary, Twin)
    : point_(primary.point_),
      settings_(primary.settings_),
      steps_per_period_(primary.steps_per_period_) {
  integrator_ = make_integrator(point_.structure, settings_);
  recording_ = integrator_->can_record_tangent();
  if (recording_) integrator_->record_tangent(true);
}

StroboscopicMap::~StroboscopicMap() = default;
StroboscopicMap::StroboscopicMap(StroboscopicMap&&) noexcept = default;
StroboscopicMap& StroboscopicMap::operator=(StroboscopicMap&&) noexcept = default;

bool StroboscopicMap::exact_tangent() const { return integrator_->has_tangent_map(); }

int StroboscopicMap::tangent_block() const {
  return state_size() >= kSpreadStateSize && integrator_->can_record_tangent() ? 2 : 1;
}

bool StroboscopicMap::splits(const Matrix& tangent) const {
  return tangent.cols() >= 2 && tangent_block() > 1 && omp_get_max_threads() > 1 &&
         !omp_in_parallel();
}

Vector StroboscopicMap::integrate(const Vector& y, double t0, double t1, Matrix* tangent) {
  if (tangent != nullptr && splits(*tangent)) return integrate_split(y, t0, t1, *tangent);
  return integrate_here(y, t0, t1, tangent);
}

Vector StroboscopicMap::integrate_split(const Vector& y, double t0, double t1, Matrix& tangent) {
  if (!twin_) twin_.reset(new StroboscopicMap(*this, Twin{}));
  const Index second = tangent.cols() / 2, first = tangent.cols() - second;
  Matrix head = tangent.leftCols(first), tail = tangent.rightCols(second);
  Vector out;
  std::exception_ptr errors[2];
  // Exceptions (a motion that blows up) are carried out of the parallel region and rethrown,
  // this map's first.
#pragma omp parallel sections num_threads(2)
  {
#pragma omp section
    {
      try {
        out = integrate_here(y, t0, t1, &head);
      } catch (...) {
        errors[0] = std::current_exception();
      }
    }
#pragma omp section
    {
      try {
        twin_->integrate_here(y, t0, t1, &tail);
      } catch (...) {
        errors[1] = std::current_exception();
      }
    }
  }
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  tangent.leftCols(first) = head;
  tangent.rightCols(second) = tail;
  return out;
}

Vector StroboscopicMap::integrate_here(const Vector& y, double t0, double t1, Matrix* tangent) {
  const Index n = dofs();
  if (y.size() != 2 * n) {
    throw InputError(fmt::format("state has {} components, the structure needs {}", y.size(),
                                 2 * n));
  }
  if (!y.allFinite()) throw InputError("state is not finite");
  if (!(t1 > t0)) throw InputError(fmt::format("arc end {} must follow its start {}", t1, t0));
  if (tangent != nullptr && replay_ready_ && t0 == base_t0_ && t1 == base_t1_ &&
      y == base_start_ && integrator_->replay_tangent(*tangent)) {
    ++replays_;
    return base_end_;
  }
  replay_ready_ = false;
  if (checkpoint_) checkpoint_();
  // Plain integrations are recorded too, over the spans whose products a shooting method takes
  // (up to kReplayPeriods forcing periods); a long transient's record would only fill memory up
  // to the integrator's bound and be dropped.
  const bool record = integrator_->can_record_tangent() &&
                      (tangent != nullptr || t1 - t0 <= kReplayPeriods * forcing_period() * (1 + 1e-12));
  if (record != recording_) {
    integrator_->record_tangent(record);
    recording_ = record;
  }
  integrator_->set_state(t0, y.head(n), y.tail(n));
  if (tangent != nullptr) {
    integrator_->advance_with_tangent(t1, *tangent);
  } else {
    integrator_->advance_to(t1);
  }
  ++evaluations_;
  Vector out(2 * n);
  out << integrator_->position(), integrator_->velocity();
  // The integrator recorded what fixes the tangent map, with or without the tangent: a product
  // from the same state over the same span (the first GMRES product after Newton's line search
  // accepted this state, say) is a replay.
  if (recording_) {
    base_start_ = y;
    base_end_ = out;
    base_t0_ = t0;
    base_t1_ = t1;
    replay_ready_ = true;
  }
  return out;
}

Vector StroboscopicMap::flow(const Vector& y, double t0, double t1, Matrix* tangent) {
  if (tangent == nullptr) return integrate(y, t0, t1, nullptr);
  if (tangent->rows() != state_size()) {
    throw InputError(fmt::format("tangent has {} rows, the state {}", tangent->rows(),
                                 state_size()));
  }
  if (exact_tangent()) return integrate(y, t0, t1, tangent);
  // Forward differences, one integration per column.
  const Vector base = integrate(y, t0, t1, nullptr);
  const double root_eps = std::sqrt(std::numeric_limits<double>::epsilon());
  for (Index c = 0; c < tangent->cols(); ++c) {
    const double norm = tangent->col(c).norm();
    if (norm == 0) continue;
    const double eps = root_eps * (1 + y.norm()) / norm;
    const Vector moved = integrate(y + eps * tangent->col(c), t0, t1, nullptr);
    tangent->col(c) = (moved - base) / eps;
  }
  return base;
}

Vector StroboscopicMap::advance(const Vector& y, int periods, int start_period) {
  if (periods < 1) throw InputError(fmt::format("periods = {} must be >= 1", periods));
  return flow(y, start_period * forcing_period(), (start_period + periods) * forcing_period());
}

Vector StroboscopicMap::advance(const Vector& y, int periods, Matrix& tangent, int start_period) {
  if (periods < 1) throw InputError(fmt::format("periods = {} must be >= 1", periods));
  return flow(y, start_period * forcing_period(), (start_period + periods) * forcing_period(),
              &tangent);
}

Vector StroboscopicMap::advance_with_jacobian(const Vector& y, int periods, Matrix& jacobian) {
  jacobian = Matrix::Identity(state_size(), state_size());
  return advance(y, periods, jacobian);
}

}  // namespace pwl::orbits
