#pragma once
// Pre-flight report of a case (issue 7): the dimensionless groups and time-step ratios that
// decide whether a run can work, computed before anything is allocated. `validate()` in
// core/case_params refuses what cannot work at all (spring limit, overfilled box, d >= W, ...);
// this report adds warnings for what is doubtful and errors for what the coupled solver cannot
// represent, with the scene's own findings (its declaration's own_checks), and is printed by
// `boycott case check` and before every `case run`.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"

namespace boycott::checks {

struct PreflightItem {
  std::string name;  ///< e.g. "Re_p"
  double value = 0.0;
  std::string unit;  ///< "" for dimensionless
  std::string meaning;
};

struct Preflight {
  std::vector<PreflightItem> items;
  std::vector<std::string> warnings;  ///< doubtful: the run goes ahead
  std::vector<std::string> errors;    ///< cannot work: the run is refused
  /// Cannot work on this machine (memory): `case run` refuses, `case check` warns (the case may
  /// be meant for a larger machine).
  std::vector<std::string> machine_errors;

  nlohmann::json to_json() const;
  /// Human-readable table, one item per line, then warnings and errors.
  std::string text() const;
};

/// Computes the report for a validated case, run on `ranks` MPI ranks of this machine (the
/// memory estimate is per rank). Never throws for physics reasons: it collects.
Preflight preflight(const CaseParams& p, int ranks = 1);

/// Memory of this machine available to the program, bytes (the cgroup limit where lower).
double machine_memory_bytes();
/// Estimated peak memory of one rank of a case on `ranks` ranks, bytes: particle and fluid
/// arrays, neighbour list, linear solver work vectors, and the checkpoint gathered on rank 0.
double memory_estimate_bytes(const CaseParams& p, int ranks);

/// The largest fluid step (s) at which a packed bed's particle-fluid exchange is stable (random
/// close packing, alpha_f 0.36; coupling/drag_stability.hpp): where numerics.drag_dt_limit is on,
/// what the step falls towards as a bed packs. Infinite for a scene without fluid or drag, or
/// particles that do not move.
double packed_bed_stable_dt_s(const CaseParams& p);

/// Binary collision time of the linear spring-dashpot for two equal spheres with restitution e
/// (s): pi / (omega_0 sqrt(1 - zeta^2)), omega_0 = sqrt(k / m_eff), m_eff = m / 2.
double collision_time_s(double mass_kg, double stiffness_n_m, double restitution);

}  // namespace boycott::checks
