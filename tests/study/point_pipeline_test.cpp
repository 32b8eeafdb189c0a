// The study pipeline: the indicator registry read back through the journal, the point model of an
// explicit structure (its named parameters, refused names), a sweep and a map of such a structure
// against the closed-form steady state of its linear motion, the observer hooks, and the method's
// capabilities deciding how λ1 is estimated.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
#include <optional>

#include "pwl/errors.hpp"
#include "pwl/study/indicators.hpp"
#include "pwl/study/parameter_sweep.hpp"
#include "pwl/study/regime_map.hpp"
#include "pwl/study/sweep_journal.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// Two unit masses in series (k = 2, 1 between ground, mass 1 and mass 2), damped by C = 0.1 I, a
// stop on mass 2 (spring 1) and a clearance spring between the masses (spring 2), forced
// sin(1.2 t) on mass 2: apps/scenes/two_mass_stop.toml.
ExplicitStructure two_mass_stop(double stop_gap = 0.2, double clearance = 0.1) {
  GapStructure g;
  Matrix m = Matrix::Identity(2, 2);
  Matrix c = 0.1 * Matrix::Identity(2, 2);
  Matrix k(2, 2);
  k << 2.0, -1.0, -1.0, 1.0;
  g.mass = to_sparse(m);
  g.damping = to_sparse(c);
  g.stiffness = to_sparse(k);
  g.springs.push_back({1, -1, 1.0, 4.0, stop_gap});
  g.springs.push_back({0, 1, -1.0, 1.0, clearance});
  g.loads.push_back({1, 1.0, 1.2, 0.0});
  return {g, "the structure of the test", "test"};
}

// The steady state of M x'' + C x' + K x = F sin(ωt) at t = kT: x = Im X, v = ω Re X with
// (K - ω² M + iω C) X = F, solved as a complex linear system.
Vector linear_steady_state(const GapStructure& g, double amplitude, double omega) {
  using Complex = std::complex<double>;
  const Index n = g.dofs();
  const Matrix m(g.mass), c(g.damping), k(g.stiffness);
  Eigen::MatrixXcd a(n, n);
  for (Index i = 0; i < n; ++i) {
    for (Index j = 0; j < n; ++j) {
      a(i, j) = Complex(k(i, j) - omega * omega * m(i, j), omega * c(i, j));
    }
  }
  Eigen::VectorXcd f = Eigen::VectorXcd::Zero(n);
  f[g.loads[0].dof] = amplitude;
  const Eigen::VectorXcd x = a.fullPivLu().solve(f);
  Vector state(2 * n);
  for (Index i = 0; i < n; ++i) {
    state[i] = x[i].imag();
    state[n + i] = omega * x[i].real();
  }
  return state;
}

bool same(const IndicatorValue& a, const IndicatorValue& b) {
  if (a.index() != b.index()) return false;
  if (const double* x = std::get_if<double>(&a)) {
    const double y = std::get<double>(b);
    return (std::isnan(*x) && std::isnan(y)) || *x == y;
  }
  return a == b;
}

}  // namespace

TEST_CASE("every registered indicator reads back through the journal", "[indicators]") {
  // A value for each row that differs from the default, whatever its type.
  PointResult r;
  int salt = 0;
  for (const Indicator& i : indicators()) {
    if (i.derived) continue;
    ++salt;
    switch (i.type) {
      case IndicatorType::text: i.set(r, fmt::format("period-{}", salt)); break;
      case IndicatorType::integer: i.set(r, static_cast<long>(salt)); break;
      case IndicatorType::real: i.set(r, -1.0 / (3.0 + salt) * std::pow(10.0, -salt)); break;
    }
  }
  r.columns = 1;
  r.poincare = {0.25};
  r.final_state = Vector::Constant(2, 1.0 / 7.0);
  const auto back = decode_record(encode_record(5, r));
  REQUIRE(back.has_value());
  CHECK(back->first == 5);
  for (const Indicator& i : indicators()) {
    INFO(i.name);
    CHECK(same(i.get(back->second), i.get(r)));
  }
  // Not computed (NaN) and empty text read back as such too.
  PointResult empty;
  const auto none = decode_record(encode_record(6, empty));
  REQUIRE(none.has_value());
  for (const Indicator& i : indicators()) {
    INFO(i.name);
    CHECK(same(i.get(none->second), i.get(empty)));
  }
  // The result files: one cell per row, in the header's order, NaN as an empty cell.
  std::string header = indicator_header();
  for (const Indicator& i : indicators()) {
    CHECK(header.rfind(std::string(i.name), 0) == 0);
    header = header.substr(std::min(header.size(), i.name.size() + 1));
  }
  CHECK(header.empty());
  CHECK(indicator_header().rfind("regime,code,period,lambda1,lambda1_error,K", 0) == 0);
  const std::string cells = indicator_cells(empty);
  CHECK(std::count(cells.begin(), cells.end(), ',') + 1 ==
        static_cast<long>(indicators().size()));
  CHECK(cells.rfind("failed,13,0,,,", 0) == 0);
  CHECK(find_indicator("lambda1") != nullptr);
  CHECK(find_indicator("no such indicator") == nullptr);
}

TEST_CASE("an explicit structure's parameters are named after its parts", "[point_model]") {
  const PointModel model(two_mass_stop());
  CHECK(model.explicit_structure());
  CHECK(model.dofs() == 2);
  CHECK(model.parameter_names() ==
        std::vector<std::string>{"spring1.stiffness", "spring1.gap", "spring2.stiffness",
                                 "spring2.gap", "load1.amplitude", "load1.frequency", "damping"});
  CHECK(model.parameter("spring2.gap") == SweepParameter::spring_gap(1));
  CHECK(model.parameter("load1.frequency").name() == "load1.frequency");
  // Unknown names and numbers out of range are refused, naming the value and the accepted names.
  for (const std::string bad : {"spring3.gap", "spring0.gap", "load2.amplitude", "spring1.width",
                                "theta", "spring.gap", "damping2", "spring1x.gap"}) {
    INFO(bad);
    try {
      model.parameter(bad);
      FAIL("accepted");
    } catch (const InputError& e) {
      const std::string what = e.what();
      CHECK(what.find('"' + bad + '"') != std::string::npos);
      CHECK(what.find("spring1.stiffness, spring1.gap") != std::string::npos);
    }
  }
  CHECK_THROWS_AS(PointModel(paper_five_dof_case("5")).parameter("spring1.gap"), InputError);
  std::string why;
  CHECK_FALSE(PointModel().has(SweepParameter::spring_gap(0), &why));
  CHECK_FALSE(model.has(SweepParameter::theta, &why));
  CHECK(why.find("theta") != std::string::npos);

  // Each parameter changes its part and nothing else; the period follows the load.
  const PointModel wider = model.with(SweepParameter::spring_gap(0), 0.7);
  CHECK(wider.structure().structure.springs[0].gap == 0.7);
  CHECK(wider.structure().structure.springs[1].gap == 0.1);
  const PointCase faster = model.with(SweepParameter::load_frequency(0), 2.4).point_case();
  CHECK(faster.period == Approx(2.0 * M_PI / 2.4).epsilon(1e-12));
  const PointCase damped = model.with(SweepParameter::damping_scale(), 3.0).point_case();
  CHECK(Matrix(damped.structure.damping)(1, 1) == Approx(0.3));
  CHECK(model.with(SweepParameter::spring_stiffness(1), 5.0).structure().structure.springs[1]
            .stiffness == 5.0);
  CHECK(model.with(SweepParameter::load_amplitude(0), -2.0).structure().structure.loads[0]
            .amplitude == -2.0);
  // Values that leave no valid case.
  CHECK_FALSE(model.accepts(SweepParameter::load_frequency(0), 0.0, &why));
  CHECK(why.find("load1.frequency = 0") != std::string::npos);
  CHECK_FALSE(model.accepts(SweepParameter::spring_stiffness(0), -1.0, &why));
  CHECK_FALSE(model.accepts(SweepParameter::damping_scale(), -1.0, &why));
  CHECK(model.accepts(SweepParameter::spring_gap(0), -0.1, &why));  // a preload is a gap too
}

TEST_CASE("a sweep of an explicit structure's gap meets the linear steady state where the stop is "
          "never reached",
          "[parameter_sweep]") {
  SweepOptions o;
  o.structure = two_mass_stop(0.2, 50.0);  // the clearance spring never closes either
  o.parameter = SweepParameter::spring_gap(0);
  o.from = 0.05;
  o.to = 100.0;
  o.points = 3;  // 0.05 (the stop is hit), 50.025 and 100 (never reached)
  o.point.transient_periods = 400;  // e^{-0.05 t}: the free motion decays below 1e-13
  o.point.recorded_periods = 100;
  o.point.components = {0, 1, 2, 3};
  std::string why;
  REQUIRE(o.is_valid(&why));
  std::map<long, PointResult> records;
  run_grid(
      o.tasks(), [&](long id) { return o.case_of(id); }, o.start_state(), o.point, {},
      [&](long id, const PointResult& r) { records.emplace(id, r); }, {2});
  REQUIRE(records.size() == 3);
  const Vector truth = linear_steady_state(o.structure->structure, 1.0, 1.2);
  const double period = 2.0 * M_PI / 1.2;
  for (long id : {1L, 2L}) {
    const PointResult& r = records.at(id);
    CHECK(r.regime == "period-1");
    for (int c = 0; c < 4; ++c) {
      CHECK(std::abs(r.poincare[r.poincare.size() - 4 + static_cast<std::size_t>(c)] - truth[c]) <
            1e-8);
    }
    // λ1 of a linear motion is its slowest decay, Re s = -c/2m = -0.05, per period.
    CHECK(std::abs(r.lambda1 - (-0.05 * period)) <= r.lambda1_error + 1e-3);
  }
  // The steady state reaches 0.05 beyond the stop: the stop is hit and the motion differs.
  CHECK(std::abs(truth[1]) > 0.05);
  CHECK(std::abs(records.at(0).poincare.back() - truth[3]) > 1e-3);
  // The unknown-parameter refusal of the whole sweep.
  o.parameter = SweepParameter::theta;
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("theta") != std::string::npos);
  o.parameter = SweepParameter::spring_gap(5);
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("spring6.gap") != std::string::npos);
  CHECK_THROWS_AS(o.chain_of(0), InputError);
}

TEST_CASE("a map of an explicit structure's gap and load amplitude", "[regime_map]") {
  RegimeMapOptions o;
  o.structure = two_mass_stop(0.2, 50.0);
  o.first = {SweepParameter::spring_gap(0), 50.0, 100.0, 2};
  o.second = {SweepParameter::load_amplitude(0), 0.5, 1.0, 2};
  o.point.transient_periods = 300;
  o.point.recorded_periods = 100;
  std::string why;
  REQUIRE(o.is_valid(&why));
  std::map<long, PointResult> cells;
  run_grid(
      o.tasks(), [&](long id) { return o.case_of(id); }, o.start_state(), o.point, {},
      [&](long id, const PointResult& r) { cells.emplace(id, r); }, {2});
  REQUIRE(cells.size() == 4);
  const double period = 2.0 * M_PI / 1.2;
  for (const auto& [id, r] : cells) {
    CHECK(r.regime == "period-1");
    CHECK(std::abs(r.lambda1 - (-0.05 * period)) <= r.lambda1_error + 1e-3);
    // The final state is the steady state of that cell's amplitude: linear in it.
    const double amplitude = o.second.value(static_cast<int>(id / 2));
    const Vector truth = linear_steady_state(o.structure->structure, amplitude, 1.2);
    CHECK((r.final_state - truth).cwiseAbs().maxCoeff() < 1e-8);
  }
  // A cell is the point of the same parameters.
  const PointResult alone = evaluate_point(o.case_of(3), o.start_state(), o.point);
  CHECK(alone.final_state == cells.at(3).final_state);
  CHECK(alone.lambda1 == cells.at(3).lambda1);
  o.second.parameter = SweepParameter::load_amplitude(1);
  CHECK_FALSE(o.is_valid(&why));
  CHECK(why.find("load2.amplitude") != std::string::npos);
}

namespace {

struct Recorder : PointObserver {
  int starts = 0;
  int periods_with_steps = 0;
  long steps = 0;
  std::vector<Vector> points;
  std::optional<Classification> classification;
  void started(const Integrator&, const PointCase&) override { ++starts; }
  StepObserver steps_of_period(int k) override {
    if (k < 48) return {};
    ++periods_with_steps;
    return [this](double, const Vector&, const Vector&) { ++steps; };
  }
  void poincare_point(int, double, const Vector& state) override { points.push_back(state); }
  void classified(const Classification& c, const PointResult&) override { classification = c; }
};

}  // namespace

TEST_CASE("an observer sees the pipeline's steps, points and classification", "[sweep_point]") {
  PointSettings s;
  s.transient_periods = 20;
  s.recorded_periods = 30;
  s.steps_per_period = 100;
  const PointCase point(paper_five_dof_case("4a"));
  Recorder recorder;
  const PointResult observed = evaluate_point(point, Vector::Zero(10), s, &recorder);
  const PointResult plain = evaluate_point(point, Vector::Zero(10), s);
  CHECK(recorder.starts == 1);
  CHECK(recorder.periods_with_steps == 3);  // periods 48, 49 and 50
  CHECK(recorder.steps == 300);
  REQUIRE(recorder.points.size() == 30);
  CHECK(recorder.points.back() == plain.final_state);
  REQUIRE(recorder.classification.has_value());
  CHECK(recorder.classification->name() == plain.regime);
  // Observing changes nothing.
  CHECK(observed.regime == plain.regime);
  CHECK(observed.lambda1 == plain.lambda1);
  CHECK(observed.final_state == plain.final_state);
}

TEST_CASE("the method's capabilities decide how λ1 is estimated", "[sweep_point]") {
  PointSettings s;
  s.transient_periods = 100;
  s.recorded_periods = 60;
  const PointCase point(PointModel(two_mass_stop(0.2, 50.0))
                            .with(SweepParameter::spring_gap(0), 50.0)
                            .point_case());
  const double decay = -0.05 * point.period;
  const PointResult vector = evaluate_point(point, Vector::Zero(4), s);
  s.lyapunov_estimate = LyapunovEstimate::tangent_frame;
  const PointResult frame = evaluate_point(point, Vector::Zero(4), s);
  CHECK(std::abs(vector.lambda1 - decay) <= vector.lambda1_error + 1e-3);
  CHECK(std::abs(frame.lambda1 - decay) <= frame.lambda1_error + 1e-3);
  CHECK(vector.final_state == frame.final_state);  // the same motion, another estimate

  // The exact solver has an exact tangent map too: the same decay from its tangent vector.
  s.method.method = Method::exact;
  s.lyapunov_estimate = LyapunovEstimate::tangent_vector;
  const PointResult exact = evaluate_point(point, Vector::Zero(4), s);
  CHECK(std::abs(exact.lambda1 - decay) <= exact.lambda1_error + 1e-3);

  // dopri5 has no tangent map: no λ1 with a tangent estimate, two nearby trajectories on request.
  s.method.method = Method::dopri5;
  s.method.tolerance = 1e-12;
  const PointResult none = evaluate_point(point, Vector::Zero(4), s);
  CHECK(std::isnan(none.lambda1));
  CHECK(none.regime == "period-1");
  s.lyapunov_estimate = LyapunovEstimate::two_trajectories;
  const PointResult two = evaluate_point(point, Vector::Zero(4), s);
  CHECK(std::abs(two.lambda1 - decay) <= two.lambda1_error + 2e-3);
  CHECK((two.final_state - vector.final_state).cwiseAbs().maxCoeff() < 1e-8);

  // Settings are checked against the method's row: a tolerance only where the method takes one.
  std::string why;
  s.method.method = Method::dopri5;
  s.method.tolerance = 0.0;
  CHECK_FALSE(s.is_valid(2, &why));
  CHECK(why.find("tolerance = 0") != std::string::npos);
  s.method.method = Method::pim;
  CHECK(s.is_valid(2, &why));
  CHECK(s.describe().find("method = PIM\n") != std::string::npos);
  s.method.method = Method::dopri5;
  s.method.tolerance = 1e-8;
  s.method.locate_kinks = true;
  CHECK(s.describe().find("method = dopri5, kink-located, tol 1e-08\n") != std::string::npos);
  CHECK(parse_lyapunov_estimate("two-trajectories") == LyapunovEstimate::two_trajectories);
  CHECK_THROWS_AS(parse_lyapunov_estimate("qr"), InputError);
}

TEST_CASE("a point whose exact integration spends its work budget fails alone", "[sweep_point]") {
  // Figure 4a's chain switches 5 to 7 times per forcing period (event_driven_solver.hpp); with a
  // budget of 2 switches per call the exact solver stops in the first period with BudgetError,
  // which a study records as a failed point (not an end of the study). With the default budget
  // the same point is classified.
  PointSettings s;
  s.transient_periods = 20;
  s.recorded_periods = 100;
  s.method.method = Method::exact;
  s.lyapunov_estimate = LyapunovEstimate::two_trajectories;
  const PointCase point(paper_five_dof_case("4a"));
  PointSettings starved = s;
  starved.method.event_driven.max_events = 2;
  const PointResult failed = evaluate_point(point, Vector::Zero(10), starved);
  CHECK(failed.regime == "failed");
  CHECK(failed.final_state.size() == 0);
  CHECK(failed.rows() == 0);
  const PointResult classified = evaluate_point(point, Vector::Zero(10), s);
  CHECK(classified.regime == "period-2");
  CHECK(classified.final_state.size() == 10);
}
