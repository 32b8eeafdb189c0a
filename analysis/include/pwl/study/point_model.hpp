#pragma once
// The model of a parameter study: what one point integrates, and the parameters a study may vary.
//
// A study varies a model. The model is either the paper's nondimensional chain (eqs 23-25), whose
// parameters are θ, α, ζ, Δ̃ and a scale of the load vector Q, or an explicit structure given by
// its matrices, gap springs and loads (a scene file's [structure] table), whose parameters are
// named after the part they change, numbered from 1 as in the scene:
//
//     spring<j>.stiffness   k_j of gap spring j
//     spring<j>.gap         Δ_j of gap spring j
//     load<j>.amplitude     the amplitude of harmonic load j
//     load<j>.frequency     the circular frequency ω of harmonic load j
//     damping               a scale of the damping matrix: C = value · (the scene's C)
//
// One point of a study is a PointCase: the structure to integrate and its forcing period, the
// period of the chain (2π/θ) or the loads' common period (GapStructure::common_period), which is
// the sampling interval of the Poincaré section.
#include <optional>
#include <string>
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/model/gap_structure.hpp"

namespace pwl::analysis {

// A parameter of a point model, by what it changes. Compared by value; the chain's five are named
// constants (SweepParameter::theta, ...), an explicit structure's are made by the factories below.
class SweepParameter {
 public:
  enum class Kind {
    theta,             // chain: forcing frequency ratio θ
    alpha,             // chain: contact stiffness ratio α of every mass
    zeta,              // chain: damping ratio ζ
    gap,               // chain: gap Δ̃ of every mass
    amplitude,         // chain: load scale, Q = value · (the base chain's Q)
    spring_stiffness,  // structure: stiffness of one gap spring
    spring_gap,        // structure: gap of one gap spring
    load_amplitude,    // structure: amplitude of one harmonic load
    load_frequency,    // structure: circular frequency of one harmonic load
    damping,           // structure: scale of the damping matrix
  };

  static const SweepParameter theta;
  static const SweepParameter alpha;
  static const SweepParameter zeta;
  static const SweepParameter gap;
  static const SweepParameter amplitude;
  // `index` is 0-based here; the name is 1-based ("spring2.gap" is spring_gap(1)).
  static SweepParameter spring_stiffness(int index) { return {Kind::spring_stiffness, index}; }
  static SweepParameter spring_gap(int index) { return {Kind::spring_gap, index}; }
  static SweepParameter load_amplitude(int index) { return {Kind::load_amplitude, index}; }
  static SweepParameter load_frequency(int index) { return {Kind::load_frequency, index}; }
  static SweepParameter damping_scale() { return {Kind::damping, -1}; }

  SweepParameter() = default;  // θ
  SweepParameter(Kind kind, int index) : kind_(kind), index_(index) {}

  Kind kind() const { return kind_; }
  int index() const { return index_; }  // spring or load, 0-based; -1 for the others
  // Whether it is a parameter of the chain (else of an explicit structure).
  bool of_chain() const { return kind_ <= Kind::amplitude; }
  // "theta", "alpha", "zeta", "gap", "amplitude", "spring2.gap", "load1.frequency", "damping".
  std::string name() const;

  friend bool operator==(const SweepParameter&, const SweepParameter&) = default;

 private:
  Kind kind_ = Kind::theta;
  int index_ = -1;
};

inline const SweepParameter SweepParameter::theta{Kind::theta, -1};
inline const SweepParameter SweepParameter::alpha{Kind::alpha, -1};
inline const SweepParameter SweepParameter::zeta{Kind::zeta, -1};
inline const SweepParameter SweepParameter::gap{Kind::gap, -1};
inline const SweepParameter SweepParameter::amplitude{Kind::amplitude, -1};

// parameter.name().
std::string parameter_name(const SweepParameter& parameter);
// One of the chain's parameters by name; also accepts "delta" for the gap. Throws InputError
// naming the value and the accepted names otherwise.
SweepParameter parse_sweep_parameter(const std::string& name);
// A copy of `base` with the chain parameter set to `value`. Throws InputError for a parameter of
// an explicit structure.
NondimensionalChain with_parameter(const NondimensionalChain& base,
                                   const SweepParameter& parameter, double value);
// A copy of `base` with the structure parameter set to `value`. Throws InputError for a chain
// parameter or a spring or load `base` does not have.
GapStructure with_parameter(const GapStructure& base, const SweepParameter& parameter,
                            double value);

// What one point integrates: the structure and its forcing period T (the Poincaré section is
// t = kT). Made implicitly from a chain, so that code that computes chains keeps working.
struct PointCase {
  GapStructure structure;
  double period = 0.0;

  PointCase(GapStructure structure, double period);
  PointCase(const NondimensionalChain& chain);  // NOLINT: make_chain(chain), chain.period()
};

// An explicit structure and where it came from (for messages, titles and study descriptions).
struct ExplicitStructure {
  GapStructure structure;
  std::string source;  // for messages and descriptions: "the structure of apps/scenes/x.toml"
  std::string label;   // short, for figure titles: "x.toml"
};

class PointModel {
 public:
  PointModel(NondimensionalChain chain = {});  // NOLINT: the chain is a model
  explicit PointModel(ExplicitStructure structure);

  bool explicit_structure() const { return structure_.has_value(); }
  // The chain (meaningful only when !explicit_structure()).
  const NondimensionalChain& chain() const { return chain_; }
  // The explicit structure. Throws Error for a chain model.
  const ExplicitStructure& structure() const;
  // Degrees of freedom (masses of the chain): the state has 2 dofs() components.
  int dofs() const;

  // Every parameter this model accepts, by name ("theta", ... or "spring1.stiffness", ...).
  std::vector<std::string> parameter_names() const;
  // The parameter called `name`. Throws InputError naming the value and the accepted names when
  // the model has no such parameter (also a spring or load number out of range).
  SweepParameter parameter(const std::string& name) const;
  // Ceres-style check: whether `parameter` belongs to this model (false with a message naming it).
  bool has(const SweepParameter& parameter, std::string* why) const;
  // Ceres-style check of one value: the model with it must be a valid structure with a forcing
  // period (θ > 0, a stiffness >= 0, a frequency that keeps the loads commensurate, ...).
  bool accepts(const SweepParameter& parameter, double value, std::string* why) const;

  // The value the model gives `parameter`, from which with() would set it: θ, ζ, and α or Δ̃ of
  // the chain when every mass has the same, 1 for the load scale (amplitude) and the damping
  // scale, a spring's stiffness or gap, a load's amplitude or frequency. Throws InputError where
  // there is no single value (masses with different α) or the model lacks the parameter.
  double value(const SweepParameter& parameter) const;
  // A copy with the parameter set to `value` (no check beyond has(); see accepts()).
  PointModel with(const SweepParameter& parameter, double value) const;
  // The structure and period to integrate. Throws InputError for an invalid model.
  PointCase point_case() const;
  // Every setting of the model, one "key = value" per line, doubles at 17 significant digits: a
  // part of a study's description (config.txt), compared on resume.
  std::string describe() const;

 private:
  NondimensionalChain chain_;
  std::optional<ExplicitStructure> structure_;
};

}  // namespace pwl::analysis
